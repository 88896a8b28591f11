#include "support/self_intersection.hpp"

#include <algorithm>

#include "support/triangle_intersection.hpp"

namespace shapectl::test {

std::string self_intersection(const Positions& x,
                              const std::vector<std::array<int, 3>>& triangles) {
  const auto corners = [&](const std::array<int, 3>& t) {
    return Triangle{x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2])};
  };
  const auto shares_a_node = [](const std::array<int, 3>& a, const std::array<int, 3>& b) {
    return std::any_of(a.begin(), a.end(),
                       [&](int i) { return i == b[0] || i == b[1] || i == b[2]; });
  };
  // Brute force over all pairs, with a box test first: slow but plainly complete.
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const Triangle a = corners(triangles[i]);
    const Vec3 lo = a[0].cwiseMin(a[1]).cwiseMin(a[2]), hi = a[0].cwiseMax(a[1]).cwiseMax(a[2]);
    for (std::size_t j = i + 1; j < triangles.size(); ++j) {
      if (shares_a_node(triangles[i], triangles[j])) continue;
      const Triangle b = corners(triangles[j]);
      const Vec3 blo = b[0].cwiseMin(b[1]).cwiseMin(b[2]), bhi = b[0].cwiseMax(b[1]).cwiseMax(b[2]);
      if ((blo.array() > hi.array()).any() || (lo.array() > bhi.array()).any()) continue;
      if (triangles_intersect(a, b))
        return "surface triangles " + std::to_string(i) + " and " + std::to_string(j) + " meet";
    }
  }
  return "";
}

}  // namespace shapectl::test
