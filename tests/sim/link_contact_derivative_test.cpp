// Contact with obstacles that move with the robot (issue 34): the contact force's θ-derivative
// for a box on a link and for the robot's own collision spheres against central differences in
// θ, and dx̂/dθ at an equilibrium resting on a box on a link against re-solved equilibria.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/sim/contact_force_jacobian.hpp>
#include <shapectl/sim/gripped_object.hpp>

#include "support/derivative_check.hpp"
#include "support/link_box_scene.hpp"
#include "support/sensitivity_check.hpp"

namespace shapectl {
namespace {

// The contact force −∂E/∂x at x with the obstacles on links placed at θ.
Eigen::VectorXd contact_force(const GrippedObject& object, const Eigen::VectorXd& theta,
                              const Positions& x) {
  const auto contact = object.moving_contact(forward_kinematics(object.robot(), theta));
  return -test::energy_gradient(*contact, x);
}

int contacts_with(const ContactSummary& s, const std::vector<Obstacle>& obstacles,
                  const std::string& name_start) {
  int count = 0;
  for (std::size_t k = 0; k < obstacles.size(); ++k)
    if (obstacles[k].name.rfind(name_start, 0) == 0) count += s.by_obstacle[k].count;
  return count;
}

TEST(LinkContact, ForceThetaDerivativeMatchesCentralDifferences) {
  // A turned box on the left arm's second link under the bar's middle, 2 mm below it, and the
  // robot's spheres with one more on the right arm's second link 2 mm under the bar at a
  // quarter of its length: every kind of pair (vertex–face, –edge, –corner; edge–edge; corner–
  // triangle; vertex–sphere) within d̂ = 5 mm.
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.3, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitX()))
          .toRotationMatrix();
  test::LinkBox b =
      test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.06, 0.04, 0.02), 0.002, turn);
  Scene& scene = b.scene;
  scene.contact.distance = 0.005;
  scene.contact.robot = true;
  const RobotModel& robot = *scene.robot->model;
  const KinematicsState reference = forward_kinematics(robot, scene.robot->reference_joints);
  std::vector<CollisionSphere> spheres = scene.robot->collisions->spheres();
  const int r_link2 = robot.link_index("r_link2");
  const double radius = 0.01;
  const Vec3 under = scene.T_world_object * Vec3(-0.08, 0.003, -0.015 - 0.002 - radius);
  spheres.push_back({r_link2, reference.T_world_link[r_link2].inverse() * under, radius});
  scene.robot->collisions = std::make_shared<const CollisionModel>(robot, spheres, 0.005, 1e6);
  GrippedObject object(scene);

  std::mt19937 rng(3);
  const Positions x = test::perturbed(object.reference_positions(), 2e-4, rng);
  const Eigen::VectorXd theta = object.reference_joints();
  const KinematicsState state = forward_kinematics(robot, theta);
  const auto contact = object.moving_contact(state);
  ASSERT_TRUE(contact);
  const ContactSummary s = contact->summary(x);
  ASSERT_GE(contacts_with(s, contact->obstacles(), "link box"), 10);
  ASSERT_GE(contacts_with(s, contact->obstacles(), "r_link2 sphere"), 1);

  const Eigen::MatrixXd analytic = contact_force_jacobian(*contact, robot, state, x);
  const Eigen::MatrixXd reference_fd = test::central_difference_jacobian(
      [&](const Eigen::VectorXd& t) -> Eigen::VectorXd { return contact_force(object, t, x); },
      theta, 1e-6);
  EXPECT_TRUE(test::derivative_matches(analytic, reference_fd, 1e-5, "∂F_contact/∂θ"));

  const Eigen::VectorXd lambda = test::perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
  Eigen::VectorXd transposed = Eigen::VectorXd::Zero(theta.size());
  add_contact_force_jacobian_transpose_times(*contact, robot, state, x, lambda, transposed);
  EXPECT_TRUE(test::derivative_matches(transposed, analytic.transpose() * lambda, 1e-12,
                                       "λᵀ∂F_contact/∂θ"));
}

TEST(LinkContact, SensitivityMatchesCentralDifferencesRestingOnALinkBox) {
  // The bar sags onto a flat box 0.5 mm under it carried by the left arm's second link, and
  // the right arm lowers its end onto it.
  test::LinkBox b =
      test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.25, 0.05, 0.02), 0.0005);
  b.scene.statics.relative_tolerance = 1e-8;
  b.scene.statics.max_iterations = 300;
  GrippedObject object(b.scene);
  Eigen::VectorXd theta = object.reference_joints();
  theta[4] += 0.004;
  ObjectState state = object.solve_from(theta, object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const auto contact = object.moving_contact(state.kinematics());
  const ContactSummary contacts = contact->summary(state.positions());
  ASSERT_GE(contacts.count, 20);

  test::expect_sensitivity_matches(object, state, 1e-4, "resting on a link box");
}

}  // namespace
}  // namespace shapectl
