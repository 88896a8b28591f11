#pragma once
// Obstacles the object may touch but not pass through (issue 34): a table, a peg, a fixture, a
// finger. Every shape is one of two kinds, so the contact code has few cases:
//   - a half-space (a plane and the side its normal points away from), or
//   - points, segments and triangles inflated by a radius: a sphere is one point, a capsule one
//     segment with radius r; a box or a mesh is its corners, edges and triangles with r = 0.
// Geometry is in the world frame, or in a robot link's frame for an obstacle attached to that
// link (it then moves with the joint angles θ: docs/contact.md, "Obstacles on robot links").
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct HalfSpace {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit; the free side is where (p − point)·normal > 0
};

struct Obstacle {
  std::string name;                // from the scene, else "obstacle N" (1-based)
  std::string shape;               // "plane", "sphere", "capsule", "box", "mesh": for messages
  std::optional<HalfSpace> plane;  // set for a plane; then the lists below are empty
  std::vector<Vec3> points;        // world, m
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangles;  // outward by the right-hand rule (box, mesh)
  double radius = 0;                          // m; > 0 for spheres and capsules
  // The robot link it is attached to (its geometry then in that link's frame); -1: the world.
  int link = -1;
  // Object nodes it never touches, sorted: those its own end effector grips (their grip springs
  // hold them; a barrier there would fight the grip).
  std::vector<int> ignored_nodes;
};

// `o` moved rigidly by T (its points and plane; name, link and ignored nodes kept).
Obstacle moved(const Obstacle& o, const Eigen::Isometry3d& T);

Obstacle make_plane(std::string name, const Vec3& point, const Vec3& normal);
Obstacle make_sphere(std::string name, const Vec3& center, double radius);
Obstacle make_capsule(std::string name, const Vec3& a, const Vec3& b, double radius);
// A box of `size` (m, full edge lengths) centred at the origin of `T_world_box`.
Obstacle make_box(std::string name, const Vec3& size, const Eigen::Isometry3d& T_world_box);
// A closed triangle surface (vertices in the world, m). Throws std::invalid_argument if it is
// not closed (an edge not shared by exactly two triangles), naming the first such edge.
Obstacle make_mesh_obstacle(std::string name, std::vector<Vec3> vertices,
                            std::vector<std::array<int, 3>> triangles);

// The scene's "contact" settings.
struct ContactSettings {
  double distance = 1e-3;  // d̂, m: the barrier acts on gaps below it
  bool self = false;       // object self-contact (self_contact.hpp)
  bool robot = false;      // the robot's collision spheres as obstacles on their links
  double friction = 0;     // Coulomb coefficient μ (contact/friction.hpp; 0: frictionless)
  // The most sub-steps a joint step is split into where obstacles on links would sweep into
  // the object on the way (quasi-static continuation, GrippedObject::solve).
  int sweep_steps = 64;
  // κ, J/m² (= N/m); none: from the object's mean nodal weight (obstacle_contact.hpp).
  std::optional<double> stiffness;
};

}  // namespace shapectl
