// dx̂/dθ through contact (issue 34): at an equilibrium resting on a table with many active
// contacts, the sensitivity from the true Hessian (barrier included) matches central differences
// of re-solved equilibria, and so does the adjoint.
#include <shapectl/sim/gripped_object.hpp>

#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace
}  // namespace shapectl
