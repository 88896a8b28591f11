#pragma once
// Whether an object's surface is clear of an obstacle, judged by tests/support's own geometry
// (triangle_intersection.hpp), not by contact/: the obstacles are described here by their
// parameters, and the test makes contact/'s Obstacle from the same numbers.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl::test {

struct ObstacleShape {
  enum class Kind { Plane, Sphere, Capsule, Box };
  Kind kind = Kind::Plane;
  Vec3 point = Vec3::Zero(), normal = Vec3::UnitZ();  // plane
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();            // sphere centre a; capsule a to b
  double radius = 0;                                  // sphere, capsule
  Vec3 size = Vec3::Ones();                           // box, centred at the pose's origin
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();

  Obstacle obstacle(const std::string& name) const;  // contact/'s make_* from these numbers
};

// The generalised winding number of the closed surface `triangles` (of points x) about p:
// ~1 inside, ~0 outside (Van Oosterom and Strackee's solid angles).
double winding_number(const Positions& x, const std::vector<std::array<int, 3>>& triangles,
                      const Vec3& p);

// Empty when the object's closed surface (triangles of positions x) neither touches nor
// intersects the shape and neither lies inside the other; otherwise what was found.
std::string intersection(const Positions& x, const std::vector<std::array<int, 3>>& triangles,
                         const ObstacleShape& shape);

}  // namespace shapectl::test
