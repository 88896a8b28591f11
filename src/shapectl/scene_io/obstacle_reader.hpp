#pragma once
// The scene's "obstacles" and "contact" (issue 34): static obstacles in the world frame and how
// contact with them acts. Part of load_scene; errors name the file and field.
#include <vector>

#include <shapectl/contact/obstacle.hpp>

namespace shapectl {

class JsonInput;

// "obstacles": [{"name"?, one of "plane" {point, normal}, "box" {size, pose}, "sphere" {center,
// radius}, "capsule" {a, b, radius}, "mesh" {file, units | scale, pose}}]. Names default to
// "obstacle N" (1-based) and must differ; "link" (an obstacle moving with a robot link) is
// refused as not supported yet.
std::vector<Obstacle> read_obstacles(const JsonInput& list);

// "contact": {"distance", "self", "robot", "friction", "stiffness"}; self or robot contact are
// refused as not supported yet; friction is a non-negative Coulomb coefficient.
ContactSettings read_contact(const JsonInput& j);

}  // namespace shapectl
