#include "support/obstacle_clearance.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "support/triangle_intersection.hpp"

namespace shapectl::test {

namespace {

Triangle triangle_of(const Positions& x, const std::array<int, 3>& t) {
  return {x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2])};
}

// A box's 12 triangles, from its corners in its own frame.
std::vector<Triangle> box_triangles(const Vec3& size, const Eigen::Isometry3d& pose) {
  auto corner = [&](int i) {
    const Vec3 s((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    return Vec3(pose * s.cwiseProduct(size));
  };
  // Each face as two triangles: faces by the fixed axis and side.
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::vector<Triangle> out;
  for (const auto& f : faces) {
    out.push_back({corner(f[0]), corner(f[1]), corner(f[2])});
    out.push_back({corner(f[0]), corner(f[2]), corner(f[3])});
  }
  return out;
}

std::string node_text(int i) { return "node " + std::to_string(i); }

}  // namespace

Obstacle ObstacleShape::obstacle(const std::string& name) const {
  switch (kind) {
    case Kind::Plane: return make_plane(name, point, normal);
    case Kind::Sphere: return make_sphere(name, a, radius);
    case Kind::Capsule: return make_capsule(name, a, b, radius);
    case Kind::Box: return make_box(name, size, pose);
  }
  return {};
}

double winding_number(const Positions& x, const std::vector<std::array<int, 3>>& triangles,
                      const Vec3& p) {
  double solid_angle = 0;
  for (const auto& t : triangles) {
    const Vec3 a = x.segment<3>(3 * t[0]) - p, b = x.segment<3>(3 * t[1]) - p,
               c = x.segment<3>(3 * t[2]) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    solid_angle += 2 * std::atan2(numerator, denominator);
  }
  return solid_angle / (4 * M_PI);
}

std::string intersection(const Positions& x, const std::vector<std::array<int, 3>>& triangles,
                         const ObstacleShape& s) {
  using Kind = ObstacleShape::Kind;
  const int n = static_cast<int>(x.size() / 3);
  if (s.kind == Kind::Plane) {
    const Vec3 normal = s.normal.normalized();
    for (int i = 0; i < n; ++i)
      if (!((x.segment<3>(3 * i) - s.point).dot(normal) > 0))
        return node_text(i) + " on or below the plane";
    return "";
  }
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const Triangle t = triangle_of(x, triangles[k]);
    const std::string what = "surface triangle " + std::to_string(k);
    if (s.kind == Kind::Sphere && !(point_triangle_distance(s.a, t) > s.radius))
      return what + " within the sphere";
    if (s.kind == Kind::Capsule && !(segment_triangle_distance(s.a, s.b, t) > s.radius))
      return what + " within the capsule";
    if (s.kind == Kind::Box)
      for (const Triangle& face : box_triangles(s.size, s.pose))
        if (triangles_intersect(t, face)) return what + " meets a face of the box";
  }
  // No surfaces meet: one could still hold the other whole.
  const Vec3 inner = s.kind == Kind::Box ? Vec3(s.pose.translation()) : s.a;
  if (winding_number(x, triangles, inner) > 0.5) return "the obstacle is inside the object";
  if (s.kind == Kind::Box) {
    const Eigen::Isometry3d to_box = s.pose.inverse();
    for (int i = 0; i < n; ++i)
      if (((to_box * Vec3(x.segment<3>(3 * i))).cwiseAbs() - s.size / 2).maxCoeff() <= 0)
        return node_text(i) + " inside the box";
  }
  return "";
}

}  // namespace shapectl::test
