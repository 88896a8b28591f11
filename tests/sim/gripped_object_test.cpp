#include <shapectl/sim/gripped_object.hpp>

#include <gtest/gtest.h>

#include <random>

#include "support/derivative_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

Eigen::VectorXd random_joints(const GrippedObject& object, double spread, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-spread, spread);
  Eigen::VectorXd theta = object.reference_joints();
  for (int j = 0; j < theta.size(); ++j) theta[j] += u(rng);
  return theta;
}

TEST(GripSprings, DerivativesMatchCentralDifferences) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  std::mt19937 rng(1);
  Positions x = object.reference_positions();
  object.solve(random_joints(object, 0.2, rng), x);
  test::expect_derivatives_match(object.grips(), test::perturbed(x, 0.002, rng), 1e-6);
}

TEST(GripSprings, ForceJacobianMatchesCentralDifferencesInJoints) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  std::mt19937 rng(2);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd theta = random_joints(object, 0.3, rng);
    const Positions x = test::perturbed(object.reference_positions(), 0.003, rng);
    Positions unused = x;
    object.solve(theta, unused);  // sets the robot state for θ
    const Eigen::MatrixXd dF = object.grips().force_jacobian(object.node_count());
    Eigen::MatrixXd dF_fd(dF.rows(), dF.cols());
    const double h = 1e-6;
    for (int j = 0; j < theta.size(); ++j) {
      auto force = [&](double dt) {
        Eigen::VectorXd t = theta;
        t[j] += dt;
        GripSprings springs = object.grips();
        springs.set_robot_state(forward_kinematics(object.robot(), t));
        Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
        springs.add_gradient(x, g);
        return Eigen::VectorXd(-g);
      };
      dF_fd.col(j) = (force(h) - force(-h)) / (2 * h);
    }
    EXPECT_LT(test::relative_error(dF, dF_fd), 1e-6);
    // The adjoint product agrees with the explicit matrix.
    const Eigen::VectorXd lambda = test::perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
    EXPECT_LT(test::relative_error(object.grips().force_jacobian_transpose_times(lambda),
                                   dF.transpose() * lambda), 1e-12);
  }
}

TEST(GrippedObject, ReferenceJointsHoldTheObjectAtItsPlacedShape) {
  Scene scene = test::two_arm_scene();
  scene.gravity = Vec3::Zero();
  GrippedObject object(scene);
  Positions x = object.reference_positions();
  const StaticsResult r = object.solve(object.reference_joints(), x);
  ASSERT_TRUE(r.converged()) << r.reason;
  EXPECT_LT((x - object.reference_positions()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(GrippedObject, CarriedGrippedNodesKeepTheirSpringLengths) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  const Eigen::VectorXd from = object.reference_joints();
  Positions x = object.reference_positions();
  ASSERT_TRUE(object.solve(from, x).converged());
  const double springs_before = object.grips().value(x);
  ASSERT_GT(springs_before, 0);  // gravity stretches them: a non-trivial check
  Eigen::VectorXd to = from;
  to << 0.3, -0.1, 0.7, -0.25, -0.45, 1.1;
  Positions carried = x;
  object.carry_gripped_nodes(from, to, x, carried);
  // A rigid motion of nodes and anchors together: every spring keeps its length.
  Positions probe = carried;
  object.solve(to, probe, 1);  // moves the anchors to `to` (one Newton step, result unused)
  EXPECT_NEAR(object.grips().value(carried), springs_before, 1e-9 * springs_before);
  // Nodes nobody grips stay where they were.
  std::vector<char> gripped(object.node_count(), 0);
  for (const auto& g : scene.grips)
    for (int i : g.nodes) gripped[i] = 1;
  for (int i = 0; i < object.node_count(); ++i)
    if (!gripped[i]) {
      EXPECT_EQ(carried.segment<3>(3 * i), x.segment<3>(3 * i));
    }
}

TEST(GrippedObject, SensitivityMatchesCentralDifferencesOfStatics) {
  Scene scene = test::two_arm_scene();
  scene.statics.relative_tolerance = 1e-11;  // FD of equilibria needs them tight
  GrippedObject object(scene);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd theta = random_joints(object, 0.25, rng);
    Positions x = object.reference_positions();
    ASSERT_TRUE(object.solve(theta, x).converged());
    const Eigen::MatrixXd dx = object.sensitivity(x);
    Eigen::MatrixXd dx_fd(dx.rows(), dx.cols());
    const double h = 1e-5;
    for (int j = 0; j < theta.size(); ++j) {
      Eigen::VectorXd tp = theta, tm = theta;
      tp[j] += h;
      tm[j] -= h;
      Positions xp = x, xm = x;
      ASSERT_TRUE(object.solve(tp, xp).converged());
      ASSERT_TRUE(object.solve(tm, xm).converged());
      dx_fd.col(j) = (xp - xm) / (2 * h);
    }
    EXPECT_LT(test::relative_error(dx, dx_fd), 1e-5) << "trial " << trial;
    ASSERT_TRUE(object.solve(theta, x).converged());
    const Eigen::VectorXd v = test::perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
    EXPECT_LT(test::relative_error(object.adjoint(x, v), dx.transpose() * v), 1e-9);
  }
}

}  // namespace
}  // namespace shapectl
