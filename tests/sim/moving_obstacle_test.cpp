// A joint move that carries an obstacle on a link into the object (issue 34). Small steps push
// the bar ahead of the box, every equilibrium clear of it by tests/support's own geometry; a
// large step that puts the box into the warm start, or would carry a thin one through the bar,
// is split where the sweep of the box reaches the bar (quasi-static continuation), never
// accepted with the bar inside the box or on its wrong side; past contact.sweep_steps it is
// refused.
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

// The equilibrium at the reference joints and the warm start carried from it to θ + size·up.
struct Step {
  ObjectState start;
  Eigen::VectorXd from, to;
  Positions x;
};
Step one_step(const GrippedObject& object, const Eigen::VectorXd& up, double size) {
  const Eigen::VectorXd theta = object.reference_joints();
  ObjectState start = object.solve_from(theta, object.reference_positions());
  EXPECT_TRUE(start.statics().converged()) << start.statics().reason;
  const Eigen::VectorXd next = theta + size * up;
  Positions x = start.positions();
  object.carry_gripped_nodes(theta, next, start.positions(), x);
  return {std::move(start), theta, next, std::move(x)};
}

// A step that puts the box ~6 mm into the warm start: solve_from (which does not know where
// the warm start came from) refuses it (Inverted); solve_along sweeps the box from the last
// joints, splits the step where it reaches the bar, and ends at the new joints, clear.
TEST(MovingObstacle, AStepThatPutsTheBoxIntoTheWarmStartIsSolvedInSubSteps) {
  const PushedBar s = pushed_bar();
  const GrippedObject object(s.box.scene);
  const auto triangles = object.mesh().surface_triangles();
  const Step step = one_step(object, s.up, 0.03);  // ~12 mm up, ~6 mm into the bar's middle
  const test::ObstacleShape moved_box = s.box.shape(forward_kinematics(object.robot(), step.to));
  ASSERT_NE(test::intersection(step.x, triangles, moved_box), "");  // the warm start is inside
  const ObjectState refused = object.solve_from(step.to, step.x);
  EXPECT_EQ(refused.statics().status, StaticsStatus::Inverted) << refused.statics().reason;
  EXPECT_NE(refused.statics().reason.find("link box"), std::string::npos);

  const ObjectState moved = object.solve_along(step.from, step.to, step.x, 0, &step.start);
  ASSERT_TRUE(moved.statics().converged()) << moved.statics().reason;
  std::cout << moved.statics().reason << ", " << moved.statics().iterations << " iterations\n";
  EXPECT_EQ(moved.joints(), step.to);
  EXPECT_NE(moved.statics().reason.find("sub-steps: obstacle 'link box'"), std::string::npos);
  EXPECT_EQ(test::intersection(moved.positions(), triangles, moved_box), "");
  EXPECT_GT(object.moving_contact(moved.kinematics())->summary(moved.positions()).count, 0);
}

// The same step with at most 2 sub-steps allowed: refused, at the new joints, saying why.
TEST(MovingObstacle, AStepNeedingMoreSubStepsThanAllowedIsRefused) {
  PushedBar s = pushed_bar();
  s.box.scene.contact.sweep_steps = 2;
  const GrippedObject object(s.box.scene);
  const Step step = one_step(object, s.up, 0.03);
  const ObjectState moved = object.solve_along(step.from, step.to, step.x, 0, &step.start);
  EXPECT_EQ(moved.statics().status, StaticsStatus::NotConverged);
  EXPECT_EQ(moved.joints(), step.to);
  EXPECT_NE(moved.statics().reason.find("obstacle 'link box' sweeps into the object"),
            std::string::npos)
      << moved.statics().reason;
  EXPECT_NE(moved.statics().reason.find("2 sub-steps (contact.sweep_steps)"), std::string::npos)
      << moved.statics().reason;
}

// A plate 2 mm thick 0.5 mm under the bar's middle, lifted ~40 mm by one joint step: where the
// step ends it is above the warm start's middle (30 mm thick), clear of it, so the warm start
// alone would let it jump through the bar. The sweep catches it: the equilibrium at the new
// joints has the plate under the bar, pushing it up, clear by tests/support's triangle test.
TEST(MovingObstacle, AThinBoxOneStepWouldCarryThroughTheBarPushesItInstead) {
  PushedBar s{test::two_arm_scene_with_link_box({24, 2, 2}, "l_link2", Vec3(0.1, 0.05, 0.002),
                                                5e-4),
              Eigen::VectorXd::Zero(6)};
  s.box.scene.contact.stiffness = 20;
  s.up = pushed_bar().up;
  const GrippedObject object(s.box.scene);
  const auto triangles = object.mesh().surface_triangles();
  const Step step = one_step(object, s.up, 0.1);
  const Positions& x = step.x;
  const test::ObstacleShape end_box = s.box.shape(forward_kinematics(object.robot(), step.to));
  // The middle of the bar: nodes within 2 cm of the plate's centre along the bar.
  const Vec3 along = object.scene().T_world_object.linear() * Vec3::UnitX();
  const auto middle_height = [&](const Positions& at) {
    double sum = 0;
    int count = 0;
    for (int i = 0; i < object.node_count(); ++i)
      if (std::abs((at.segment<3>(3 * i) - end_box.pose.translation()).dot(along)) < 0.02) {
        sum += at[3 * i + 2];
        ++count;
      }
    return sum / count;
  };
  ASSERT_EQ(test::intersection(x, triangles, end_box), "");  // clear where the step ends...
  ASSERT_GT(end_box.pose.translation().z(), middle_height(x) + 0.015);  // ...above the bar
  // Solved from there without the sweep, the bar ends above the plate: it jumped through.
  const ObjectState jumped = object.solve_from(step.to, x);
  ASSERT_TRUE(jumped.statics().converged()) << jumped.statics().reason;
  EXPECT_GT(end_box.pose.translation().z(), middle_height(jumped.positions()) + 0.015);

  const ObjectState moved = object.solve_along(step.from, step.to, x, 0, &step.start);
  ASSERT_TRUE(moved.statics().converged()) << moved.statics().reason;
  std::cout << moved.statics().reason << ", " << moved.statics().iterations << " iterations\n";
  EXPECT_EQ(test::intersection(moved.positions(), triangles, end_box), "");
  EXPECT_LT(end_box.pose.translation().z(), middle_height(moved.positions()) - 0.015);
  EXPECT_GT(object.moving_contact(moved.kinematics())->summary(moved.positions()).count, 0);
}

}  // namespace
}  // namespace shapectl
