#pragma once
// Lower bounds on the distance between two convex hulls of a few points (a point, a segment, a
// triangle) from separating axes: along any direction u they are at least as far apart as their
// projections on u. Plain doubles, a handful of dot products: the broad phase drops with them
// the pairs that are surely farther apart than it cares about before the exact (and far dearer)
// distance. Any u gives a true bound, however it was computed; round-off only enters the
// projections (~1e-16 of the coordinates).
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <shapectl/types.hpp>

namespace shapectl {

// The gap between the projections of the hulls of `a` and `b` on u, over |u| (≤ 0 where they
// overlap; -inf for u = 0).
template <std::size_t A, std::size_t B>
double axis_gap(const std::array<Vec3, A>& a, const std::array<Vec3, B>& b, const Vec3& u) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double length = u.norm();
  if (!(length > 0)) return -inf;
  double a_min = inf, a_max = -inf, b_min = inf, b_max = -inf;
  for (const Vec3& p : a) {
    const double s = u.dot(p);
    a_min = std::min(a_min, s);
    a_max = std::max(a_max, s);
  }
  for (const Vec3& p : b) {
    const double s = u.dot(p);
    b_min = std::min(b_min, s);
    b_max = std::max(b_max, s);
  }
  return std::max(b_min - a_max, a_min - b_max) / length;
}

// Point p – triangle abc: the axes of the triangle's normal and of its edges' normals in its
// plane (which separate a point beside the triangle in its plane).
inline double point_triangle_separation(const Vec3& p, const Vec3& a, const Vec3& b,
                                        const Vec3& c) {
  const std::array<Vec3, 1> point{p};
  const std::array<Vec3, 3> triangle{a, b, c};
  const Vec3 n = (b - a).cross(c - a);
  double gap = axis_gap(point, triangle, n);
  for (int k = 0; k < 3; ++k)
    gap = std::max(gap, axis_gap(point, triangle, n.cross(triangle[(k + 1) % 3] - triangle[k])));
  return gap;
}

// Segment pq – segment rs: their common normal, each one's normal in the plane of both (for
// segments side by side in one plane), and each one's normal towards the other's start (for
// parallel segments, whose common normal vanishes).
inline double segment_segment_separation(const Vec3& p, const Vec3& q, const Vec3& r,
                                         const Vec3& s) {
  const std::array<Vec3, 2> first{p, q}, second{r, s};
  const Vec3 d1 = q - p, d2 = s - r, n = d1.cross(d2);
  double gap = axis_gap(first, second, n);
  gap = std::max(gap, axis_gap(first, second, d1.cross(n)));
  gap = std::max(gap, axis_gap(first, second, d2.cross(n)));
  gap = std::max(gap, axis_gap(first, second, d1.cross((r - p).cross(d1))));
  return std::max(gap, axis_gap(first, second, d2.cross((p - r).cross(d2))));
}

// Triangle abc – triangle def: both normals and each one's edge normals in its own plane.
inline double triangle_triangle_separation(const std::array<Vec3, 3>& t,
                                           const std::array<Vec3, 3>& u) {
  double gap = -std::numeric_limits<double>::infinity();
  for (const auto* one : {&t, &u}) {
    const std::array<Vec3, 3>& v = *one;
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    gap = std::max(gap, axis_gap(t, u, n));
    for (int k = 0; k < 3; ++k) gap = std::max(gap, axis_gap(t, u, n.cross(v[(k + 1) % 3] - v[k])));
  }
  return gap;
}

}  // namespace shapectl
