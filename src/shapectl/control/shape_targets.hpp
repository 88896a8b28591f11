#pragma once
// What the user asks for: target positions p'ᵢ for some mesh nodes (world frame, metres).
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct ShapeTargets {
  std::vector<int> nodes;
  std::vector<Vec3> positions;  // one per node
  bool empty() const { return nodes.empty(); }
  int size() const { return static_cast<int>(nodes.size()); }
};

// The paper's error: mean (and max) Euclidean distance of targeted nodes from their targets.
struct ShapeError {
  double mean = 0;
  double max = 0;
};
ShapeError shape_error(const ShapeTargets& targets, const Positions& x);

}  // namespace shapectl
