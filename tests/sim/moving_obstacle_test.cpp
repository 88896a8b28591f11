// A joint move that carries an obstacle on a link into the object (issue 34). Small steps push
// the bar ahead of the box, every equilibrium clear of it by tests/support's own geometry; one
// large step that puts the box into the warm start is refused (Inverted), never accepted with
// the bar inside the box.
#include <gtest/gtest.h>

#include <shapectl/sim/gripped_object.hpp>

#include "support/link_box_scene.hpp"
#include "support/obstacle_clearance.hpp"

namespace shapectl {
namespace {

struct PushedBar {
  test::LinkBox box;
  Eigen::VectorXd up;  // a unit joint step lifting the box into the bar (left arm's joint 2)
};

// A flat box on the left arm's second link 0.5 mm under the bar's middle. Joint 2 lifts the
// box and the bar's left end alike; the right end stays, so the box rises into the middle.
PushedBar pushed_bar() {
  PushedBar s{test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.1, 0.05, 0.02), 5e-4),
              {}};
  // A contact stiff enough for the arm's push (the default suits the bar's weight alone).
  s.box.scene.contact.stiffness = 20;
  s.up = test::lifting_step(s.box, 1);
  return s;
}

TEST(MovingObstacle, SmallStepsPushTheBarAndEveryEquilibriumIsClear) {
  const PushedBar s = pushed_bar();
  const GrippedObject object(s.box.scene);
  const auto triangles = object.mesh().surface_triangles();
  Eigen::VectorXd theta = object.reference_joints();
  ObjectState state = object.solve_from(theta, object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  int touching = 0;
  int refused = 0;
  for (int step = 0; step < 20; ++step) {
    // The optimizer's warm start: the first-order prediction, gripped nodes carried exactly.
    const Eigen::VectorXd next = theta + 5e-4 * s.up;
    Positions x = state.positions() + object.sensitivity(state) * (next - theta);
    object.carry_gripped_nodes(theta, next, state.positions(), x);
    ObjectState moved = object.solve_from(next, x);
    if (!moved.statics().converged()) {  // an honest failure is allowed, a state inside not
      ++refused;
      break;
    }
    EXPECT_EQ(test::intersection(moved.positions(), triangles, s.box.shape(moved.kinematics())), "")
        << "step " << step;
    touching += object.moving_contact(moved.kinematics())->summary(moved.positions()).count > 0;
    theta = next;
    state = std::move(moved);
  }
  EXPECT_GE(touching, 5);  // the box did push the bar
}

TEST(MovingObstacle, AStepThatPutsTheBoxIntoTheWarmStartIsRefused) {
  const PushedBar s = pushed_bar();
  const GrippedObject object(s.box.scene);
  const auto triangles = object.mesh().surface_triangles();
  const Eigen::VectorXd theta = object.reference_joints();
  ObjectState state = object.solve_from(theta, object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const Eigen::VectorXd next = theta + 0.03 * s.up;  // ~12 mm up, ~6 mm into the bar's middle
  Positions x = state.positions();
  object.carry_gripped_nodes(theta, next, state.positions(), x);
  const test::ObstacleShape moved_box = s.box.shape(forward_kinematics(object.robot(), next));
  ASSERT_NE(test::intersection(x, triangles, moved_box), "");  // the warm start is inside
  const ObjectState moved = object.solve_from(next, x);
  EXPECT_EQ(moved.statics().status, StaticsStatus::Inverted) << moved.statics().reason;
  EXPECT_NE(moved.statics().reason.find("link box"), std::string::npos) << moved.statics().reason;
}

}  // namespace
}  // namespace shapectl
