// An unreachable target on the bundled YuMi + foam bar (issue 36 item 2), through the controller
// the GUI drives: the same target gives the same reasons whatever the optimizer's path (the
// same start five times, and after other targets), reach named as the binding cause, and why
// the optimizer stopped where it did.
#include <shapectl/control/controller.hpp>

#include <gtest/gtest.h>

#include <shapectl/control/reach_bound.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

class YumiBarUnreachable : public ::testing::Test {
 protected:
  Scene scene = load_scene(test::source_path("scenes/yumi_bar.json"));
  GrippedObject object{scene};
  // The node nearest the bar's middle, and a target `up` m above it.
  int middle() const {
    const Positions& x = object.reference_positions();
    Vec3 centre = Vec3::Zero();
    for (int i = 0; i < object.node_count(); ++i) centre += x.segment<3>(3 * i);
    centre /= object.node_count();
    int best = 0;
    for (int i = 1; i < object.node_count(); ++i)
      if ((x.segment<3>(3 * i) - centre).norm() < (x.segment<3>(3 * best) - centre).norm())
        best = i;
    return best;
  }
  ShapeTargets above(double up) const {
    ShapeTargets t;
    t.nodes = {middle()};
    t.positions = {object.reference_positions().segment<3>(3 * middle()) + Vec3(0, 0, up)};
    return t;
  }
};

// Steps the controller (no thread) until it stops for `targets`.
std::shared_ptr<const ControllerSnapshot> stop_at(Controller& controller,
                                                  const ShapeTargets& targets) {
  controller.set_targets(targets);
  for (int k = 0; k < 2000; ++k) {
    controller.step_once();
    const auto s = controller.snapshot();
    if (s->targets.positions == targets.positions && s->status != ControllerStatus::Optimizing)
      return s;
  }
  ADD_FAILURE() << "the controller did not stop in 2000 iterations";
  return controller.snapshot();
}

// The words of one reason ("reach: …") in a status line.
std::string clause(const std::string& status_reason, const std::string& reason) {
  const auto from = status_reason.find(reason + ": ");
  if (from == std::string::npos) return {};
  return status_reason.substr(from, status_reason.find("; ", from) - from);
}

TEST_F(YumiBarUnreachable, TheSameTargetGivesTheSameReasonsFromAnyStart) {
  const ShapeTargets far = above(1.2);
  std::vector<std::shared_ptr<const ControllerSnapshot>> runs;
  for (int k = 0; k < 5; ++k) {
    Controller controller(scene);
    runs.push_back(stop_at(controller, far));
  }
  // From another target's pose: 0.6 m above first, and the bar bent sideways.
  for (const Vec3& before : {Vec3(0, 0, 0.6), Vec3(0, 0.1, -0.05)}) {
    Controller controller(scene);
    ShapeTargets other = far;
    other.positions[0] = object.reference_positions().segment<3>(3 * middle()) + before;
    stop_at(controller, other);
    runs.push_back(stop_at(controller, far));
  }
  for (const auto& s : runs) {
    EXPECT_EQ(s->status, ControllerStatus::BestEffort) << s->status_reason;
    EXPECT_EQ(s->shortfalls, std::vector<Shortfall>{Shortfall::Reach}) << s->status_reason;
    EXPECT_EQ(clause(s->status_reason, "reach"), clause(runs[0]->status_reason, "reach"));
    EXPECT_NE(s->status_reason.find("it reaches with that node unstretched"), std::string::npos)
        << s->status_reason;
    // And why the optimizer stopped where it did, in numbers.
    EXPECT_NE(s->status_reason.find("; the optimizer stopped: "), std::string::npos)
        << s->status_reason;
  }
  // From the same start the whole path is the same: the same pose and the same words.
  for (int k = 1; k < 5; ++k) {
    EXPECT_EQ(runs[k]->joints, runs[0]->joints);
    EXPECT_EQ(runs[k]->status_reason, runs[0]->status_reason);
  }
}

TEST_F(YumiBarUnreachable, ATargetWithinReachIsNoQuestionOfReach) {
  // 0.6 m above: within what the arms reach with the bar unstretched, so whatever stops the
  // optimizer, it is not named reach from the target alone.
  EXPECT_EQ(beyond_unstretched_reach(object, above(0.6)), "");
  EXPECT_NE(beyond_unstretched_reach(object, above(1.2)), "");
}

}  // namespace
}  // namespace shapectl
