#pragma once
// TARGETS.json: {"targets": [{"node": i, "position": [x, y, z]}, …]} or
// {"centerline": [[x, y, z], …]} (world frame, metres).
#include <filesystem>
#include <vector>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/io/json_input.hpp>

namespace shapectl {

struct TargetsInput {
  ShapeTargets targets;          // explicit node targets (empty for a centre-line)
  std::vector<Vec3> centerline;  // the polyline (empty for node targets)
};

// Throws InputError naming the file and field: node out of range, non-finite numbers, empty
// lists, repeated nodes, a centre-line with fewer than 2 distinct points.
TargetsInput read_targets(const JsonInput& json, int node_count);
TargetsInput load_targets(const std::filesystem::path& file, int node_count);

}  // namespace shapectl
