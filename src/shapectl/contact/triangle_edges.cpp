#include <shapectl/contact/triangle_edges.hpp>

#include <algorithm>

namespace shapectl {

std::vector<std::array<int, 2>> triangle_edges(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::array<int, 2>> edges;
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3];
      edges.push_back({std::min(i, j), std::max(i, j)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

std::vector<int> triangle_corners(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<int> corners;
  for (const auto& t : triangles) corners.insert(corners.end(), t.begin(), t.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  return corners;
}

}  // namespace shapectl
