// Each best-effort reason, from a state built to have it: the reason is found, and the others
// that do not hold are not claimed. (Buckling has no case here: the two-arm robot cannot push
// the bar's ends together without turning its grips, which bends the bar smoothly instead.)
#include <shapectl/control/shortfall.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <shapectl/robot/collision_spheres.hpp>

#include "support/linear_solvers.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

// A new evaluation for find_shortfalls, which may factor its state (it lives to the end of
// the call's full expression).
Evaluation& fresh(Evaluation&& e) { return e; }

bool has(const ShortfallReport& r, Shortfall s) {
  return std::find(r.reasons.begin(), r.reasons.end(), s) != r.reasons.end();
}

// Every third node, aimed at `x` moved by `offset`.
ShapeTargets targets_at(const Positions& x, const Vec3& offset = Vec3::Zero()) {
  ShapeTargets t;
  for (int i = 0; 3 * i < x.size(); i += 3) {
    t.nodes.push_back(i);
    t.positions.push_back(x.segment<3>(3 * i) + offset);
  }
  return t;
}

Eigen::VectorXd joints(double l1, double l2, double l3, double r1, double r2, double r3) {
  Eigen::VectorXd theta(6);
  theta << l1, l2, l3, r1, r2, r3;
  return theta;
}

// Each reason found alike with each linear solver (support/linear_solvers.hpp).
class ShortfallEachSolver : public test::EachLinearSolver {};

TEST_P(ShortfallEachSolver, JointAtItsLimitThatTheTargetsPushFurther) {
  Scene scene = with_solver(test::two_arm_scene());
  // l3 may bend only to 0.95 rad; the reference holds it at 0.9, inside the 0.05 margin.
  std::string urdf = test::two_arm_urdf();
  const std::string limit = "<limit lower='-2.5' upper='2.5'";
  urdf.replace(urdf.find(limit), limit.size(), "<limit lower='-2.5' upper='0.95'");
  scene.robot->model =
      std::make_shared<RobotModel>(RobotModel::from_urdf_string(urdf, "two_arms.urdf"));
  const GrippedObject object(scene);
  const ReducedObjective probe(object);
  // The targets: the shape with l3 bent past its limit.
  const Evaluation goal =
      probe.evaluate(joints(0, -0.3, 1.2, 0, -0.3, 0.9), object.reference_positions());
  ASSERT_TRUE(goal.statics().converged());
  const ReducedObjective objective = probe.with_targets(targets_at(goal.positions()));
  Evaluation at = objective.evaluate(object.reference_joints(), object.reference_positions());
  const ShortfallReport r = find_shortfalls(objective, at);
  EXPECT_TRUE(has(r, Shortfall::JointLimit)) << r.detail;
  EXPECT_NE(r.detail.find("l3 "), std::string::npos) << r.detail;
  EXPECT_NE(r.detail.find("upper limit"), std::string::npos) << r.detail;
  EXPECT_FALSE(has(r, Shortfall::Collision)) << r.detail;
  EXPECT_FALSE(has(r, Shortfall::Reach)) << r.detail;
  // Targets that pull l3 back from the limit: no joint-limit reason.
  const Evaluation back =
      probe.evaluate(joints(0, -0.3, 0.6, 0, -0.3, 0.9), object.reference_positions());
  const ReducedObjective away = probe.with_targets(targets_at(back.positions()));
  EXPECT_FALSE(has(find_shortfalls(away, fresh(away.evaluate(at.joints(), at.positions()))),
                   Shortfall::JointLimit));
}

TEST_P(ShortfallEachSolver, SpheresWithinTheMarginThatTheTargetsPushTogether) {
  // The third links' spheres 4 mm apart at the reference, inside the 5 mm margin.
  const Scene scene = with_solver(test::two_arm_scene_with_clearance(0.004));
  const GrippedObject object(scene);
  const ReducedObjective probe(object);
  const Evaluation at = probe.evaluate(object.reference_joints(), object.reference_positions());
  // The targets: the shape with the arms swung towards each other.
  const Evaluation goal = probe.evaluate(test::arms_swung_in(0.01), at.positions(), 0, &at);
  ASSERT_TRUE(at.statics().converged() && goal.statics().converged());
  const ReducedObjective objective = probe.with_targets(targets_at(goal.positions()));
  const ShortfallReport r =
      find_shortfalls(objective, fresh(objective.evaluate(at.joints(), at.positions())));
  EXPECT_TRUE(has(r, Shortfall::Collision)) << r.detail;
  EXPECT_NE(r.detail.find("l_link3–r_link3 clearance 4.0 mm"), std::string::npos) << r.detail;
  EXPECT_FALSE(has(r, Shortfall::JointLimit)) << r.detail;
  // Targets that swing the arms apart: no collision reason.
  const Evaluation apart = probe.evaluate(test::arms_swung_in(-0.01), at.positions(), 0, &at);
  const ReducedObjective opening = probe.with_targets(targets_at(apart.positions()));
  EXPECT_FALSE(has(find_shortfalls(opening, fresh(opening.evaluate(at.joints(), at.positions()))),
                   Shortfall::Collision));
}

TEST_P(ShortfallEachSolver, ArmsStretchedTowardsTargetsBeyondTheirReach) {
  const Scene scene = with_solver(test::two_arm_scene());
  const GrippedObject object(scene);
  const ReducedObjective probe(object);
  // Both arms straight up (their full 0.55 m), the targets 20 cm above the bar held there.
  const Evaluation up =
      probe.evaluate(joints(0, -M_PI / 2, 0, 0, -M_PI / 2, 0), object.reference_positions());
  ASSERT_TRUE(up.statics().converged()) << up.statics().reason;
  const ReducedObjective objective = probe.with_targets(targets_at(up.positions(), {0, 0, 0.2}));
  const ShortfallReport r =
      find_shortfalls(objective, fresh(objective.evaluate(up.joints(), up.positions())));
  EXPECT_TRUE(has(r, Shortfall::Reach)) << r.detail;
  EXPECT_NE(r.detail.find("left arm stretched to 100 %"), std::string::npos) << r.detail;
  EXPECT_FALSE(has(r, Shortfall::JointLimit)) << r.detail;
  // Beyond what the arms reach with the bar unstretched, so reach binds and is the only reason.
  EXPECT_EQ(r.reasons, std::vector<Shortfall>{Shortfall::Reach}) << r.detail;
  EXPECT_EQ(r.detail.find("reach: node "), 0u) << r.detail;
  // At the reference the arms are bent: the targets still say reach (from the targets alone,
  // whatever the pose), with the same words, but no arm is stretched there.
  const ShortfallReport bent =
      find_shortfalls(objective, fresh(objective.evaluate(object.reference_joints(),
                                                          object.reference_positions())));
  EXPECT_EQ(bent.reasons, std::vector<Shortfall>{Shortfall::Reach}) << bent.detail;
  EXPECT_EQ(bent.detail.substr(0, bent.detail.find(';')), r.detail.substr(0, r.detail.find(';')));
  EXPECT_EQ(bent.detail.find("stretched to"), std::string::npos) << bent.detail;
}

TEST_P(ShortfallEachSolver, NoneOfTheFourIsALocalMinimumSaidAsSuch) {
  const Scene scene = with_solver(test::two_arm_scene());
  const GrippedObject object(scene);
  const ReducedObjective probe(object);
  // A target 5 cm below the bar's middle at the reference: nothing limits the arms there.
  const ReducedObjective objective =
      probe.with_targets(targets_at(object.reference_positions(), {0, 0, -0.05}));
  const ShortfallReport r =
      find_shortfalls(objective, fresh(objective.evaluate(object.reference_joints(),
                                                          object.reference_positions())));
  EXPECT_TRUE(r.reasons.empty()) << r.detail;
  EXPECT_NE(r.detail.find("local minimum"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Each, ShortfallEachSolver, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

}  // namespace
}  // namespace shapectl
