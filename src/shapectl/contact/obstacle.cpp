#include <shapectl/contact/obstacle.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>

#include <shapectl/contact/triangle_edges.hpp>

namespace shapectl {

namespace {

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw std::invalid_argument("obstacle '" + name + "': " + what);
}

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void require_finite(const std::string& name, const char* field, const Vec3& v) {
  if (!v.allFinite()) fail(name, std::string(field) + ": expected finite coordinates");
}

void require_positive(const std::string& name, const char* field, double v) {
  if (!(v > 0) || !std::isfinite(v))
    fail(name, std::string(field) + ": expected a positive number, got " + text(v));
}

}  // namespace

Obstacle make_plane(std::string name, const Vec3& point, const Vec3& normal) {
  require_finite(name, "point", point);
  require_finite(name, "normal", normal);
  if (!(normal.norm() > 0)) fail(name, "normal: expected a non-zero vector");
  Obstacle o;
  o.name = std::move(name);
  o.shape = "plane";
  o.plane = HalfSpace{point, normal.normalized()};
  return o;
}

Obstacle make_sphere(std::string name, const Vec3& center, double radius) {
  require_finite(name, "center", center);
  require_positive(name, "radius", radius);
  Obstacle o;
  o.name = std::move(name);
  o.shape = "sphere";
  o.points = {center};
  o.radius = radius;
  return o;
}

Obstacle make_capsule(std::string name, const Vec3& a, const Vec3& b, double radius) {
  require_finite(name, "a", a);
  require_finite(name, "b", b);
  require_positive(name, "radius", radius);
  Obstacle o;
  o.name = std::move(name);
  o.shape = "capsule";
  o.points = {a, b};
  o.edges = {{0, 1}};
  o.radius = radius;
  return o;
}

Obstacle make_box(std::string name, const Vec3& size, const Eigen::Isometry3d& T_world_box) {
  for (int k = 0; k < 3; ++k) require_positive(name, "size", size[k]);
  Obstacle o;
  o.name = std::move(name);
  o.shape = "box";
  // Corner i has bit k set where it lies on the + side of axis k.
  for (int i = 0; i < 8; ++i) {
    const Vec3 sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    o.points.push_back(T_world_box * (0.5 * size.cwiseProduct(sign)).eval());
  }
  // Each face: its four corners around it, two triangles, turned to face outward.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = 1 << ((axis + 1) % 3), v = 1 << ((axis + 2) % 3), w = side << axis;
      const std::array<int, 4> q{w, w | u, w | u | v, w | v};
      const Vec3 normal = (o.points[q[1]] - o.points[q[0]]).cross(o.points[q[2]] - o.points[q[0]]);
      const Vec3 outward = o.points[q[0]] - T_world_box.translation();
      if (normal.dot(outward) > 0) {
        o.triangles.push_back({q[0], q[1], q[2]});
        o.triangles.push_back({q[0], q[2], q[3]});
      } else {
        o.triangles.push_back({q[0], q[2], q[1]});
        o.triangles.push_back({q[0], q[3], q[2]});
      }
    }
  o.edges = triangle_edges(o.triangles);
  return o;
}

Obstacle make_mesh_obstacle(std::string name, std::vector<Vec3> vertices,
                            std::vector<std::array<int, 3>> triangles) {
  if (triangles.empty()) fail(name, "the mesh has no triangles");
  for (std::size_t v = 0; v < vertices.size(); ++v)
    if (!vertices[v].allFinite()) fail(name, "vertex " + std::to_string(v) + " is not finite");
  const int n = static_cast<int>(vertices.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    for (int i : tri)
      if (i < 0 || i >= n)
        fail(name, "triangle " + std::to_string(t) + ": vertex " + std::to_string(i) +
                       " out of range (the mesh has " + std::to_string(n) + " vertices)");
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0])
      fail(name, "triangle " + std::to_string(t) + " repeats a vertex");
  }
  // Closed: every edge in exactly two triangles.
  std::map<std::array<int, 2>, int> uses;
  for (const auto& tri : triangles)
    for (int k = 0; k < 3; ++k) {
      const int i = tri[k], j = tri[(k + 1) % 3];
      ++uses[{std::min(i, j), std::max(i, j)}];
    }
  for (const auto& [edge, count] : uses)
    if (count != 2)
      fail(name, "the mesh is not closed: edge " + std::to_string(edge[0]) + "-" +
                     std::to_string(edge[1]) + " is in " + std::to_string(count) +
                     " triangle(s), expected 2");
  Obstacle o;
  o.name = std::move(name);
  o.shape = "mesh";
  o.points = std::move(vertices);
  o.edges = triangle_edges(triangles);
  o.triangles = std::move(triangles);
  return o;
}

Obstacle moved(const Obstacle& o, const Eigen::Isometry3d& T) {
  Obstacle out = o;
  for (Vec3& p : out.points) p = T * p;
  if (out.plane) out.plane = HalfSpace{T * o.plane->point, T.linear() * o.plane->normal};
  return out;
}

}  // namespace shapectl
