#pragma once
// The edges and the vertices of a triangle list, each once.
#include <array>
#include <vector>

namespace shapectl {

// Every edge of the triangles once, as {lower vertex, higher vertex}, sorted.
std::vector<std::array<int, 2>> triangle_edges(const std::vector<std::array<int, 3>>& triangles);
// Every vertex of the triangles once, sorted.
std::vector<int> triangle_corners(const std::vector<std::array<int, 3>>& triangles);

}  // namespace shapectl
