// The reach bound (issue 36 item 11): what it adds up on a robot built in code, that no pose nor
// equilibrium exceeds it, and the message of a target beyond it.
#include <shapectl/control/reach_bound.hpp>

#include <gtest/gtest.h>

#include <random>

#include "support/test_support.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

const ArmReach& arm_of(const std::vector<ArmReach>& arms, const RobotModel& robot,
                       const char* link) {
  for (const ArmReach& arm : arms)
    if (arm.link == robot.link_index(link)) return arm;
  throw std::runtime_error(std::string("no arm grips with ") + link);
}

TEST(ReachBound, AnArmStartsAtItsFirstJointAndAddsUpItsLinks) {
  const Scene scene = test::two_arm_scene();
  const GrippedObject object(scene);
  const std::vector<ArmReach> arms = reach_bounds(object);
  ASSERT_EQ(arms.size(), 2u);
  const ArmReach& left = arm_of(arms, object.robot(), "l_tool");
  EXPECT_EQ(object.robot().joints()[left.base_joint].name, "l1");
  EXPECT_EQ(left.base, Vec3(0, 0.15, 0));
  // Joint 2 at 0.1 m, joint 3 at 0.25 m, the tool at 0.2 m: 0.55 m of arm, then the grip.
  const double spring = object.statics().weight() / scene.grip_stiffness;
  for (const GrippedNode& g : object.grips().nodes()) {
    if (g.link != left.link) continue;
    double anchor = 0;
    for (const GrippedNode& h : object.grips().nodes())
      if (h.link == g.link) anchor = std::max(anchor, h.point_link.norm());
    EXPECT_NEAR(left.node_bound[g.node], 0.55 + anchor + spring, 1e-12);
  }
  // A node away from the grips adds its path through the object, stretched tenfold.
  double largest = 0;
  for (double b : left.node_bound) largest = std::max(largest, b);
  const double bar = scene.object_mesh->bounds_max().x() - scene.object_mesh->bounds_min().x();
  EXPECT_GT(largest, 0.55 + max_edge_stretch * (bar - 0.04));
}

TEST(ReachBound, NoPoseNorEquilibriumGoesBeyondIt) {
  const Scene scene = test::two_arm_scene();
  const GrippedObject object(scene);
  const std::vector<ArmReach> arms = reach_bounds(object);
  const RobotModel& robot = object.robot();
  const Eigen::VectorXd lower = robot.lower_limits(), upper = robot.upper_limits();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  double closest = INFINITY;  // how near a pose comes to the arm part of the bound
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::VectorXd theta(robot.active_count());
    for (int j = 0; j < theta.size(); ++j) theta[j] = lower[j] + unit(rng) * (upper[j] - lower[j]);
    const std::vector<Vec3> anchors = object.grips().anchors(forward_kinematics(robot, theta));
    for (std::size_t k = 0; k < anchors.size(); ++k) {
      const GrippedNode& g = object.grips().nodes()[k];
      for (const ArmReach& arm : arms) {
        if (arm.link != g.link) continue;
        const double slack = arm.node_bound[g.node] - (anchors[k] - arm.base).norm();
        EXPECT_GE(slack, 0) << "trial " << trial;
        closest = std::min(closest, slack);
      }
    }
  }
  EXPECT_LT(closest, 0.1);  // the arm part is near tight: some pose comes within 10 cm of it
  // Equilibria at poses about the reference: every node within its bound from every arm.
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd theta = object.reference_joints();
    for (int j = 0; j < theta.size(); ++j) theta[j] += 0.2 * (unit(rng) - 0.5);
    const ObjectState state = object.solve_from(theta, object.reference_positions());
    ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
    for (const ArmReach& arm : arms)
      for (int n = 0; n < object.node_count(); ++n)
        EXPECT_LE((state.positions().segment<3>(3 * n) - arm.base).norm(), arm.node_bound[n]);
  }
}

TEST(ReachBound, ATargetBeyondIsRefusedNamingItAndTheBound) {
  const Scene scene = test::two_arm_scene();
  const GrippedObject object(scene);
  const Positions x = object.reference_positions();
  ShapeTargets targets;
  targets.nodes = {0, 5};
  targets.positions = {x.segment<3>(0), x.segment<3>(15)};
  EXPECT_EQ(test::input_error_of([&] { check_targets_in_reach(object, targets, "t.json"); }), "");
  targets.positions[1] = Vec3(529, 0, 0);
  const std::string error =
      test::input_error_of([&] { check_targets_in_reach(object, targets, "t.json"); });
  EXPECT_EQ(error.rfind("t.json: targets[1]: target 529 m from joint '", 0), 0u) << error;
  EXPECT_NE(error.find("; the robot reaches at most "), std::string::npos) << error;
  EXPECT_NE(error.find(" with node 5 (coordinates are metres unless the file gives \"units\""),
            std::string::npos)
      << error;
  const std::vector<Vec3> line = {x.segment<3>(0), Vec3(0, -529, 0)};
  EXPECT_EQ(test::input_error_of([&] {
              check_centerline_in_reach(object, line, "c.json");
            }).rfind("c.json: centerline[1]: point ", 0),
            0u);
  EXPECT_EQ(test::input_error_of([&] {
              check_centerline_in_reach(object, {x.segment<3>(0), x.segment<3>(15)}, "c.json");
            }),
            "");
}

}  // namespace
}  // namespace shapectl
