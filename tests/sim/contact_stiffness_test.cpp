// The adaptive barrier stiffness (issue 34, sim/contact_stiffness.hpp): an arm pressing a box
// on its link into the bar with the default κ (made for the bar's weight alone) ends at gaps of
// at least d̂/100, κ raised; dx̂/dθ at such a state is the derivative of the equilibria solved
// at its κ; a scene whose obstacle is never within d̂ keeps κ and its equilibria.
#include <shapectl/sim/contact_stiffness.hpp>

#include <gtest/gtest.h>

#include <functional>
#include <iostream>

#include <shapectl/sim/gripped_object.hpp>

#include "support/link_box_scene.hpp"
#include "support/obstacle_clearance.hpp"
#include "support/sensitivity_check.hpp"

namespace shapectl {
namespace {

// A box on the left arm's second link 0.5 mm under the bar's middle (moving_obstacle_test's
// scene, κ left at its default). Joint 2 lifts the box and the bar's left end alike; the right
// end stays, so the box rises into the middle. `up`: the unit joint step that lifts the box.
struct PushedBar {
  test::LinkBox box;
  Eigen::VectorXd up;
};

PushedBar pushed_bar() {
  // Turned and tilted a little: with its edges parallel to the bar's (moving_obstacle_test's
  // box) Newton's line search fails at gaps near d̂/6 with the default κ, no gap pressed, so
  // nothing this test is about (the edge–edge pairs there, most likely).
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.3, Vec3::UnitZ()) * Eigen::AngleAxisd(0.05, Vec3::UnitX()))
          .toRotationMatrix();
  PushedBar s{test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.1, 0.05, 0.02), 5e-4,
                                                turn),
              {}};
  s.box.scene.statics.relative_tolerance = 1e-8;  // finite differences of equilibria need it
  s.box.scene.statics.max_iterations = 300;
  s.up = test::lifting_step(s.box, 1);
  return s;
}

// The optimizer's way from the reference joints: `steps` joint steps of `step` rad along `up`,
// each warm-started by the first-order prediction (gripped nodes carried) with the last state as
// the chord. Stops at the first step that does not converge (the test then fails on it).
ObjectState walk(const GrippedObject& object, const Eigen::VectorXd& up, double step, int steps,
                 const std::function<void(const ObjectState&)>& visit = {}) {
  ObjectState state = object.solve_from(object.reference_joints(), object.reference_positions());
  EXPECT_TRUE(state.statics().converged()) << state.statics().reason;
  for (int k = 0; k < steps && state.statics().converged(); ++k) {
    const Eigen::VectorXd next = state.joints() + step * up;
    Positions x = state.positions() + object.sensitivity(state) * (next - state.joints());
    object.carry_gripped_nodes(state.joints(), next, state.positions(), x);
    ObjectState moved = object.solve_from(next, x, 0, &state);
    EXPECT_TRUE(moved.statics().converged()) << "step " << k << ": " << moved.statics().reason;
    if (visit) visit(moved);
    state = std::move(moved);
  }
  return state;
}

TEST(ContactStiffness, AnArmPressingABoxIntoTheBarEndsAtGapsOfAtLeastAHundredthOfDhat) {
  const PushedBar s = pushed_bar();
  const GrippedObject object(s.box.scene);
  const double dhat = s.box.scene.contact.distance;
  const auto triangles = object.mesh().surface_triangles();
  int touching = 0;
  double smallest = dhat;
  const ObjectState last = walk(object, s.up, 5e-4, 20, [&](const ObjectState& state) {
    const ContactSummary c = object.contact_at(state)->summary(state.positions());
    touching += c.count > 0;
    smallest = std::min(smallest, c.min_distance);
    EXPECT_EQ(test::intersection(state.positions(), triangles, s.box.shape(state.kinematics())),
              "");
  });
  std::cout << touching << " equilibria touching the box; smallest gap " << smallest
            << " m; contact stiffness ×" << last.contact_scale() << " ("
            << object.contact_at(last)->stiffness() << " N/m) at the last\n";
  EXPECT_GE(touching, 5);  // the box did press the bar
  EXPECT_GE(smallest, pressed_gap * dhat);
  EXPECT_GT(last.contact_scale(), 1);  // the default κ was raised to get there
  EXPECT_DOUBLE_EQ(object.contact_at(last)->stiffness(),
                   last.contact_scale() * object.statics().contact()->stiffness());
}

TEST(ContactStiffness, SensitivityAtARaisedStiffnessMatchesEquilibriaSolvedAtIt) {
  const PushedBar s = pushed_bar();
  const GrippedObject object(s.box.scene);
  ObjectState state = walk(object, s.up, 5e-4, 12);
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  ASSERT_GT(state.contact_scale(), 1);
  ASSERT_GE(object.contact_at(state)->summary(state.positions()).count, 10);

  // Each re-solved at the state's κ (which stays: its gaps are far above d̂/100).
  test::expect_sensitivity_matches(object, state, 1e-4, "at a raised contact stiffness");
}

TEST(ContactStiffness, AnObstacleNeverWithinDhatChangesNothing) {
  // The box 5 cm under the bar: the same walk with and without it.
  PushedBar s = pushed_bar();
  s.box = test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.1, 0.05, 0.02), 0.05);
  Scene without = s.box.scene;
  without.obstacles.clear();
  const GrippedObject far(s.box.scene), none(without);
  int iterations_far = 0, iterations_none = 0;
  const ObjectState a = walk(far, s.up, 5e-4, 6, [&](const ObjectState& state) {
    iterations_far += state.statics().iterations;
    EXPECT_EQ(state.contact_scale(), 1);
    EXPECT_EQ(far.contact_at(state)->summary(state.positions()).count, 0);
  });
  const ObjectState b = walk(none, s.up, 5e-4, 6, [&](const ObjectState& state) {
    iterations_none += state.statics().iterations;
  });
  EXPECT_EQ(iterations_far, iterations_none);
  EXPECT_LT((a.positions() - b.positions()).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace shapectl
