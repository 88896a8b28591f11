#pragma once
// The obstacles of a scene's contact term (docs/contact.md): the scene's own, fixed in the world
// or on a robot link, and with contact.robot the robot's collision spheres, each a sphere on its
// link. Nodes an end effector grips are held by its grip springs: the obstacles of its own links
// ignore them (a barrier there would fight the grip).
#include <vector>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl {

// The links that are an end effector's own, as flags per link: the subtree below the last
// active joint on the way from its link to the root (for the YuMi: link 7, the gripper and its
// fingers). Without an active joint above it, just the subtree of its link.
std::vector<char> end_effector_links(const RobotModel& robot, int link);

// The scene's obstacles, then the robot's spheres if contact.robot (named "<link> sphere N",
// 1-based per link), each on a link given the nodes it ignores.
std::vector<Obstacle> contact_obstacles(const Scene& scene);

}  // namespace shapectl
