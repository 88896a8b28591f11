// dx̂/dθ through contact (issue 34): at an equilibrium resting on a table with many active
// contacts, and at one where the object touches itself, the sensitivity from the true Hessian
// (barrier included) matches central differences of re-solved equilibria, and so does the
// adjoint.
#include <shapectl/sim/gripped_object.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>

#include <shapectl/contact/obstacle_contact.hpp>

#include "support/sensitivity_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

TEST(ContactSensitivity, MatchesCentralDifferencesWithTwentyActiveContacts) {
  // The two arms' bar over a table 0.5 mm under its bottom face, lowered onto it.
  Scene scene = test::two_arm_scene({24, 2, 2});
  const Positions rest = scene.world_rest_positions();
  double bottom = INFINITY;
  for (int i = 0; i < static_cast<int>(rest.size() / 3); ++i)
    bottom = std::min(bottom, rest[3 * i + 2]);
  scene.obstacles.push_back(make_plane("table", Vec3(0, 0, bottom - 0.5e-3), Vec3::UnitZ()));
  scene.statics.relative_tolerance = 1e-8;  // FD of equilibria needs them tight (1e-10: round-off)
  scene.statics.max_iterations = 300;
  GrippedObject object(scene);
  Eigen::VectorXd theta = object.reference_joints();
  theta[0] += 0.1, theta[3] += 0.1;      // swung sideways over the table
  theta[1] += 0.004, theta[4] += 0.004;  // and lowered onto it
  ObjectState state = object.solve_from(theta, object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const ContactSummary contacts = object.statics().contact()->summary(state.positions());
  ASSERT_GE(contacts.count, 20);
  ASSERT_GT(contacts.force_total.z(), 0);

  test::expect_sensitivity_matches(object, state, 1e-4, "in contact");
}

// A 0.32 × 0.03 × 0.03 m foam bar (the YuMi scene's) held by its middle cross-section in the
// left tool of the two arms' robot, its ends pushed down and towards each other (`force` N each,
// at 45°) until they touch under it (as in self_contact_statics_test).
Scene u_bar(double force) {
  Scene scene = test::two_arm_scene();
  const KinematicsState ref =
      forward_kinematics(*scene.robot->model, scene.robot->reference_joints);
  scene.object_mesh =
      std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, {16, 2, 2}));
  scene.material = material_from_youngs(2e5, 0.3, 40);
  scene.T_world_object = Eigen::Isometry3d::Identity();
  scene.T_world_object.translation() =
      ref.T_world_link[scene.robot->end_effectors[0].link].translation();
  scene.grips.assign(1, Grip{});
  scene.grips[0].end_effector = 0;
  scene.loads.assign(2, NodeLoad{});
  for (int i = 0; i < scene.object_mesh->node_count(); ++i) {
    const double x = scene.object_mesh->rest_positions()[i].x();
    if (std::abs(x) < 1e-6) scene.grips[0].nodes.push_back(i);
    if (std::abs(std::abs(x) - 0.16) < 1e-6) scene.loads[x < 0 ? 0 : 1].nodes.push_back(i);
  }
  scene.loads[0].force = force * Vec3(1, 0, -1).normalized();
  scene.loads[1].force = force * Vec3(-1, 0, -1).normalized();
  scene.contact.self = true;
  scene.statics.relative_tolerance = 1e-8;  // FD of equilibria needs them tight
  scene.statics.max_iterations = 300;
  return scene;
}

TEST(ContactSensitivity, MatchesCentralDifferencesWithTheObjectTouchingItself) {
  const double force = 8;
  const int steps = 4;
  Positions x = u_bar(0).world_rest_positions();
  const Eigen::VectorXd theta = GrippedObject(u_bar(0)).reference_joints();
  for (int k = 1; k < steps; ++k) {  // the load raised in steps, each from the last
    const ObjectState s = GrippedObject(u_bar(force * k / steps)).solve_from(theta, x);
    ASSERT_TRUE(s.statics().converged()) << "step " << k << ": " << s.statics().reason;
    x = s.positions();
  }
  const GrippedObject object(u_bar(force));
  ObjectState state = object.solve_from(theta, x);
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const SelfContact& self = *object.statics().self_contact();
  ElementNodes pairs;
  self.hessian_elements(state.positions(), pairs);
  std::cout << pairs.size() << " self-contact pairs within d̂, smallest gap "
            << self.min_distance(state.positions()) << " m\n";
  ASSERT_GE(pairs.size(), 1u);  // 2 on the 2026-11-28 run, at a gap of 0.14 mm

  x = state.positions();
  const Eigen::MatrixXd dx = object.sensitivity(state);
  const auto equilibrium = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    const ObjectState moved = object.solve_from(t, x);
    EXPECT_TRUE(moved.statics().converged()) << moved.statics().reason;
    return moved.positions();
  };
  const auto check =
      test::derivative_matches(dx, test::central_difference_jacobian(equilibrium, theta, 1e-5),
                               1e-4, "dx/dθ touching itself");
  std::cout << check.message() << "\n";
  EXPECT_TRUE(check);
}

}  // namespace
}  // namespace shapectl
