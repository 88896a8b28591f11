#pragma once
// Whether a deformed surface passes through itself, judged with tests/support's own exact
// triangle–triangle test (not contact/'s): every pair of surface triangles sharing no node.
#include <array>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl::test {

// The first two triangles of `triangles` (node indices into x) that share no node and meet at
// x, described; empty when there are none.
std::string self_intersection(const Positions& x, const std::vector<std::array<int, 3>>& triangles);

}  // namespace shapectl::test
