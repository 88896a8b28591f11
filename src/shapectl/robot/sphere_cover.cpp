#include <shapectl/robot/sphere_cover.hpp>

#include <algorithm>
#include <cmath>

namespace shapectl {

namespace {

// Cells per axis for an extent: cells about `cell` long, at least one, at most the cap.
int cells_for(double extent, double cell) {
  if (!(cell > 0) || !(extent > 0)) return 1;
  const double n = std::ceil(extent / cell - 1e-9);
  return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(max_cover_cells_per_axis)));
}

// Cell edge: the smallest extent, but no smaller than the largest extent over the cap.
double cell_edge(const Vec3& size) {
  return std::max(size.minCoeff(), size.maxCoeff() / max_cover_cells_per_axis);
}

struct Grid {
  Vec3 min;
  Vec3 step;
  std::array<int, 3> cells;
  Vec3 cell_min(int i, int j, int k) const { return min + step.cwiseProduct(Vec3(i, j, k)); }
  // Circumscribed sphere of a cell, a hair larger so round-off never leaves a corner outside.
  double radius() const { return 0.5 * step.norm() * (1 + 1e-12) + 1e-15; }
};

Grid make_grid(const Vec3& min, const Vec3& size) {
  const double edge = cell_edge(size);
  Grid g{min,
         Vec3::Zero(),
         {cells_for(size.x(), edge), cells_for(size.y(), edge), cells_for(size.z(), edge)}};
  for (int a = 0; a < 3; ++a) g.step[a] = size[a] / g.cells[a];
  return g;
}

// Parity of crossings of a ray from p along a fixed generic direction: true when p is inside a
// closed mesh.
bool inside_closed_mesh(const Vec3& p, const std::vector<Vec3>& v,
                        const std::vector<std::array<int, 3>>& triangles) {
  const Vec3 dir = Vec3(0.5773, 0.5774, 0.5775).normalized() + Vec3(1e-3, 2.3e-3, -1.7e-3);
  int crossings = 0;
  for (const auto& t : triangles) {
    // Möller–Trumbore
    const Vec3 e1 = v[t[1]] - v[t[0]], e2 = v[t[2]] - v[t[0]];
    const Vec3 h = dir.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-300) continue;
    const Vec3 s = p - v[t[0]];
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Vec3 q = s.cross(e1);
    const double w = dir.dot(q) / det;
    if (w < 0 || u + w > 1) continue;
    if (e2.dot(q) / det > 0) ++crossings;
  }
  return crossings % 2 == 1;
}

bool closed(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::pair<int, int>> edges;
  for (const auto& t : triangles)
    for (int a = 0; a < 3; ++a) edges.emplace_back(std::minmax(t[a], t[(a + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) return false;
    i = j;
  }
  return !edges.empty();
}

}  // namespace

std::vector<CoverSphere> cover_box(const Vec3& size) {
  const Grid g = make_grid(-0.5 * size, size);
  std::vector<CoverSphere> spheres;
  for (int i = 0; i < g.cells[0]; ++i)
    for (int j = 0; j < g.cells[1]; ++j)
      for (int k = 0; k < g.cells[2]; ++k)
        spheres.push_back({g.cell_min(i, j, k) + 0.5 * g.step, g.radius()});
  return spheres;
}

std::vector<CoverSphere> cover_cylinder(double radius, double length) {
  // Slices about as long as the radius: sphere radius √(r² + (h/2)²) ≤ 1.12 r.
  const int n = cells_for(length, std::max(radius, length / max_cover_cells_per_axis));
  const double h = length / n;
  const double r = std::sqrt(radius * radius + 0.25 * h * h) * (1 + 1e-12) + 1e-15;
  std::vector<CoverSphere> spheres;
  for (int i = 0; i < n; ++i) spheres.push_back({Vec3(0, 0, -0.5 * length + (i + 0.5) * h), r});
  return spheres;
}

std::vector<CoverSphere> cover_shape(const Shape& shape) {
  std::vector<CoverSphere> local;
  switch (shape.kind) {
    case Shape::Kind::Sphere: local = {{Vec3::Zero(), shape.radius}}; break;
    case Shape::Kind::Box: local = cover_box(shape.box_size); break;
    case Shape::Kind::Cylinder: local = cover_cylinder(shape.radius, shape.length); break;
    case Shape::Kind::Mesh: break;  // a mesh file: cover_triangle_mesh once it is read
  }
  for (auto& s : local) s.center = shape.T_link_shape * s.center;
  return local;
}

std::vector<CoverSphere> cover_triangle_mesh(const std::vector<Vec3>& vertices,
                                             const std::vector<std::array<int, 3>>& triangles) {
  if (triangles.empty()) return {};
  Vec3 lo = vertices[triangles[0][0]], hi = lo;
  for (const auto& t : triangles)
    for (int a : t) {
      lo = lo.cwiseMin(vertices[a]);
      hi = hi.cwiseMax(vertices[a]);
    }
  const Grid g = make_grid(lo, hi - lo);
  std::vector<char> used(static_cast<std::size_t>(g.cells[0] * g.cells[1] * g.cells[2]), 0);
  auto at = [&](int i, int j, int k) -> char& {
    return used[static_cast<std::size_t>((i * g.cells[1] + j) * g.cells[2] + k)];
  };
  // A cell whose box overlaps a triangle's bounding box may touch it: conservative, never misses.
  auto index_range = [&](double a, double b, int axis) {
    if (!(g.step[axis] > 0)) return std::pair<int, int>{0, g.cells[axis] - 1};
    const int first = static_cast<int>(std::floor((a - g.min[axis]) / g.step[axis] - 1e-9));
    const int last = static_cast<int>(std::floor((b - g.min[axis]) / g.step[axis] + 1e-9));
    return std::pair<int, int>{std::clamp(first, 0, g.cells[axis] - 1),
                               std::clamp(last, 0, g.cells[axis] - 1)};
  };
  for (const auto& t : triangles) {
    const Vec3 tlo = vertices[t[0]].cwiseMin(vertices[t[1]]).cwiseMin(vertices[t[2]]);
    const Vec3 thi = vertices[t[0]].cwiseMax(vertices[t[1]]).cwiseMax(vertices[t[2]]);
    const auto [i0, i1] = index_range(tlo.x(), thi.x(), 0);
    const auto [j0, j1] = index_range(tlo.y(), thi.y(), 1);
    const auto [k0, k1] = index_range(tlo.z(), thi.z(), 2);
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j)
        for (int k = k0; k <= k1; ++k) at(i, j, k) = 1;
  }
  // A cell no triangle touches is wholly inside or wholly outside: its centre tells which.
  const bool is_closed = closed(triangles);
  std::vector<CoverSphere> spheres;
  for (int i = 0; i < g.cells[0]; ++i)
    for (int j = 0; j < g.cells[1]; ++j)
      for (int k = 0; k < g.cells[2]; ++k) {
        const Vec3 center = g.cell_min(i, j, k) + 0.5 * g.step;
        if (at(i, j, k) || (is_closed && inside_closed_mesh(center, vertices, triangles)))
          spheres.push_back({center, g.radius()});
      }
  return spheres;
}

}  // namespace shapectl
