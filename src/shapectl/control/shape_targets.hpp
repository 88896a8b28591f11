#pragma once
// What the user asks for: target positions p'ᵢ for some mesh nodes (world frame, metres).
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// Targets are within reach of a robot, not kilometres off (beyond, squared distances in the
// objective lose all meaning long before they overflow).
inline constexpr double max_target_distance = 1e3;  // m from the world origin

struct ShapeTargets {
  std::vector<int> nodes;
  std::vector<Vec3> positions;  // one per node
  bool empty() const { return nodes.empty(); }
  int size() const { return static_cast<int>(nodes.size()); }
};

// Throws InputError naming `source` and the target ("targets[3].position: expected a finite
// point within 1000 m of the origin, got [1e+155, 0, 0]") unless every node is in
// [0, node_count) and every position finite and within max_target_distance.
void check_targets(const ShapeTargets& targets, int node_count, const std::string& source);
// The same check for one point (a target or a centre-line point) named `where`.
void check_target_point(const Vec3& p, const std::string& source, const std::string& where);

// The paper's error: mean (and max) Euclidean distance of targeted nodes from their targets.
struct ShapeError {
  double mean = 0;
  double max = 0;
};
ShapeError shape_error(const ShapeTargets& targets, const Positions& x);

}  // namespace shapectl
