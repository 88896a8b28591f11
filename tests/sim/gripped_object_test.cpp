#include <shapectl/sim/gripped_object.hpp>

#include <gtest/gtest.h>

#include <random>

#include "support/derivative_check.hpp"
#include "support/linear_solvers.hpp"
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
  const ObjectState state =
      object.solve_from(random_joints(object, 0.2, rng), object.reference_positions());
  const GripEnergy grip(object.grips(), state.kinematics());
  test::expect_derivatives_match(grip, test::perturbed(state.positions(), 0.002, rng), 1e-6);
}

TEST(GripSprings, ForceJacobianMatchesCentralDifferencesInJoints) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  std::mt19937 rng(2);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd theta = random_joints(object, 0.3, rng);
    const Positions x = test::perturbed(object.reference_positions(), 0.003, rng);
    const KinematicsState kinematics = forward_kinematics(object.robot(), theta);
    const Eigen::MatrixXd dF = object.grips().force_jacobian(kinematics, object.node_count());
    const auto force = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
      const GripEnergy springs(object.grips(), forward_kinematics(object.robot(), t));
      return -test::energy_gradient(springs, x);
    };
    EXPECT_TRUE(test::derivative_matches(dF, test::central_difference_jacobian(force, theta, 1e-6),
                                         1e-6, "grip force Jacobian in joints"));
    // The adjoint product agrees with the explicit matrix.
    const Eigen::VectorXd lambda = test::perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
    EXPECT_TRUE(
        test::derivative_matches(object.grips().force_jacobian_transpose_times(kinematics, lambda),
                                 dF.transpose() * lambda, 1e-12,
                                 "grip force Jacobian transpose times"));
  }
}

TEST(GrippedObject, ReferenceJointsHoldTheObjectAtItsPlacedShape) {
  Scene scene = test::two_arm_scene();
  scene.gravity = Vec3::Zero();
  GrippedObject object(scene);
  const ObjectState state =
      object.solve_from(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  EXPECT_LT((state.positions() - object.reference_positions()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(GrippedObject, CarriedGrippedNodesKeepTheirSpringLengths) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  const Eigen::VectorXd from = object.reference_joints();
  const ObjectState state = object.solve_from(from, object.reference_positions());
  ASSERT_TRUE(state.statics().converged());
  const Positions& x = state.positions();
  const double springs_before = GripEnergy(object.grips(), state.kinematics()).value(x);
  ASSERT_GT(springs_before, 0);  // gravity stretches them: a non-trivial check
  Eigen::VectorXd to = from;
  to << 0.3, -0.1, 0.7, -0.25, -0.45, 1.1;
  Positions carried = x;
  object.carry_gripped_nodes(from, to, x, carried);
  // A rigid motion of nodes and anchors together: every spring keeps its length.
  const GripEnergy moved(object.grips(), forward_kinematics(object.robot(), to));
  EXPECT_NEAR(moved.value(carried), springs_before, 1e-9 * springs_before);
  // Nodes nobody grips stay where they were.
  std::vector<char> gripped(object.node_count(), 0);
  for (const auto& g : scene.grips)
    for (int i : g.nodes) gripped[i] = 1;
  for (int i = 0; i < object.node_count(); ++i)
    if (!gripped[i]) {
      EXPECT_EQ(carried.segment<3>(3 * i), x.segment<3>(3 * i));
    }
}

// Sensitivities from each linear solver's factor (support/linear_solvers.hpp).
class GrippedObjectEachSolver : public test::EachLinearSolver {};

TEST_P(GrippedObjectEachSolver, SensitivityMatchesCentralDifferencesOfStatics) {
  Scene scene = with_solver(test::two_arm_scene());
  scene.statics.relative_tolerance = 1e-11;  // FD of equilibria needs them tight
  GrippedObject object(scene);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd theta = random_joints(object, 0.25, rng);
    ObjectState state = object.solve_from(theta, object.reference_positions());
    ASSERT_TRUE(state.statics().converged());
    const Positions x = state.positions();
    const Eigen::MatrixXd dx = object.sensitivity(state);
    // The equilibrium re-solved at each perturbed θ, warm-started from x̂(θ).
    const auto equilibrium = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
      const ObjectState moved = object.solve_from(t, x);
      EXPECT_TRUE(moved.statics().converged()) << moved.statics().reason;
      return moved.positions();
    };
    EXPECT_TRUE(
        test::derivative_matches(dx, test::central_difference_jacobian(equilibrium, theta, 1e-5),
                                 1e-5, "sensitivity dx/dθ"))
        << "trial " << trial;
    const Eigen::VectorXd v = test::perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
    EXPECT_TRUE(test::derivative_matches(object.adjoint(state, v), dx.transpose() * v, 1e-9,
                                         "adjoint (dx/dθ)ᵀv"));
  }
}

INSTANTIATE_TEST_SUITE_P(Each, GrippedObjectEachSolver, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

// The same check with the perturbed equilibria re-solved by Krylov steps (conjugate gradients
// preconditioned with x̂(θ)'s factorization, each to Eisenstat–Walker's relative residual
// between StaticsOptions::krylov_first_forcing and krylov_tolerance), chord steps off: Newton
// stops on the true residual, so the central differences are of exact equilibria and still
// match the sensitivities to 1e-5.
TEST(GrippedObject, SensitivityMatchesCentralDifferencesWithKrylovResolves) {
  Scene scene = test::two_arm_scene();
  scene.statics.relative_tolerance = 1e-11;
  scene.statics.chord_steps = false;
  GrippedObject object(scene);
  std::mt19937 rng(5);
  int krylov_steps = 0, factorizations = 0;
  for (int trial = 0; trial < 2; ++trial) {
    const Eigen::VectorXd theta = random_joints(object, 0.25, rng);
    ObjectState state = object.solve_from(theta, object.reference_positions());
    ASSERT_TRUE(state.statics().converged());
    const Positions x = state.positions();
    const Eigen::MatrixXd dx = object.sensitivity(state);  // factors at x̂: the preconditioner
    const auto equilibrium = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
      const ObjectState moved = object.solve_from(t, x, 0, &state);
      EXPECT_TRUE(moved.statics().converged()) << moved.statics().reason;
      for (const auto& it : moved.statics().log) krylov_steps += it.krylov > 0;
      factorizations += moved.statics().factorizations;
      return moved.positions();
    };
    EXPECT_TRUE(
        test::derivative_matches(dx, test::central_difference_jacobian(equilibrium, theta, 1e-5),
                                 1e-5, "sensitivity dx/dθ, Krylov re-solves"))
        << "trial " << trial;
  }
  EXPECT_GT(krylov_steps, 0);
  EXPECT_EQ(factorizations, 0);
}

}  // namespace
}  // namespace shapectl
