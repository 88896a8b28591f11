// The robot's spheres as obstacles (contact.robot) on the YuMi bar (issue 34): the nodes an end
// effector grips sit inside its fingers' spheres, so they must not contact its own obstacles
// (the grip holds them); a sphere on another link does push the bar.
#include <gtest/gtest.h>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/contact_obstacles.hpp>
#include <shapectl/sim/gripped_object.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

Scene yumi_bar_with_robot_contact() {
  Scene scene = load_scene(test::source_path("scenes/yumi_bar.json"));
  scene.contact.robot = true;
  return scene;
}

TEST(GripperExclusion, TheYumiBarSolvesAtTheReferenceWithItsFingersAroundTheGrippedNodes) {
  const Scene scene = yumi_bar_with_robot_contact();
  const RobotModel& robot = *scene.robot->model;
  const KinematicsState reference = forward_kinematics(robot, scene.robot->reference_joints);
  const Positions x = scene.world_rest_positions();
  // Without the exclusion the start would be refused: a finger sphere holds a gripped node.
  int held_inside = 0;
  for (const Grip& g : scene.grips) {
    const std::vector<char> own =
        end_effector_links(robot, scene.robot->end_effectors[g.end_effector].link);
    for (const CollisionSphere& s : scene.robot->collisions->spheres()) {
      if (!own[s.link]) continue;
      const Vec3 c = reference.T_world_link[s.link] * s.center_link;
      for (int i : g.nodes) held_inside += (x.segment<3>(3 * i) - c).norm() < s.radius;
    }
  }
  ASSERT_GT(held_inside, 0);

  GrippedObject object(scene);
  ObjectState state = object.solve_from(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  // The fingers' spheres touch no node there: the gripped ones are theirs to ignore, the rest
  // clear of them. (The gripper bases' coarse spheres may touch the nodes next to the grip.)
  const ContactSummary s = object.statics().contact()->summary(state.positions());
  const auto& obstacles = object.statics().contact()->obstacles();
  for (const ContactPoint& p : s.points) {
    EXPECT_GT(p.distance, 0);
    EXPECT_EQ(obstacles[p.obstacle].name.find("finger"), std::string::npos)
        << obstacles[p.obstacle].name << " touches the bar at a gap of " << p.distance;
  }
}

TEST(GripperExclusion, ASphereOnAnotherLinkPushesTheBar) {
  Scene scene = yumi_bar_with_robot_contact();
  const RobotModel& robot = *scene.robot->model;
  const KinematicsState reference = forward_kinematics(robot, scene.robot->reference_joints);
  // A sphere on the left arm's sixth link (not its gripper's), 0.3 mm over the bar's middle.
  const int link = robot.link_index("yumi_link_6_l");
  const double radius = 0.01;
  const Vec3 over = scene.T_world_object * Vec3(0, 0, 0.015 + 0.0003 + radius);
  std::vector<CollisionSphere> spheres = scene.robot->collisions->spheres();
  spheres.push_back({link, reference.T_world_link[link].inverse() * over, radius});
  scene.robot->collisions =
      std::make_shared<const CollisionModel>(robot, spheres, scene.robot->collisions->margin(),
                                             scene.robot->collisions->stiffness());
  GrippedObject object(scene);
  ObjectState state = object.solve_from(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const ContactSummary s = object.statics().contact()->summary(state.positions());
  const auto& obstacles = object.statics().contact()->obstacles();
  int pushed = 0;
  for (const ContactPoint& p : s.points)
    if (obstacles[p.obstacle].link == link) {
      ++pushed;
      EXPECT_LT(p.force.z(), 0);  // down onto the bar
    }
  EXPECT_GT(pushed, 0);
  EXPECT_GT(s.min_distance, 0);
}

}  // namespace
}  // namespace shapectl
