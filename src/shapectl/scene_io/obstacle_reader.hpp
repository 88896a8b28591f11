#pragma once
// The scene's "obstacles" and "contact" (issue 34): obstacles in the world or on robot links and
// how contact with them acts. Part of load_scene; errors name the file and field.
#include <vector>

#include <shapectl/contact/obstacle.hpp>

namespace shapectl {

class JsonInput;
struct RobotSetup;

// "obstacles": [{"name"?, "link"?, one of "plane" {point, normal}, "box" {size, pose}, "sphere"
// {center, radius}, "capsule" {a, b, radius}, "mesh" {file, units | scale, pose}}]. Names
// default to "obstacle N" (1-based) and must differ. With "link" (a link of `robot`, refused
// without one) the obstacle moves with that link, its geometry in the link's frame; a plane
// cannot.
std::vector<Obstacle> read_obstacles(const JsonInput& list, const RobotSetup* robot);

// "contact": {"distance", "self", "robot", "friction", "stiffness"}; robot: true needs `robot`
// with collision spheres; friction is a non-negative Coulomb coefficient.
ContactSettings read_contact(const JsonInput& j, const RobotSetup* robot);

}  // namespace shapectl
