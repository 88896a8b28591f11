#pragma once
// TARGETS.json: {"targets": [{"node": i, "position": [x, y, z]}, …]} or
// {"centerline": [[x, y, z], …]} (world frame), with "units": "m" (default), "cm" or "mm" for
// the coordinates; read in metres.
#include <filesystem>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include <shapectl/control/shape_targets.hpp>

namespace shapectl {

class JsonInput;

struct TargetsInput {
  ShapeTargets targets;          // explicit node targets (empty for a centre-line)
  std::vector<Vec3> centerline;  // the polyline (empty for node targets)
};

inline constexpr std::size_t max_target_count = 100'000;
inline constexpr std::size_t max_centerline_points = 100'000;

// Throws InputError naming the file and field: node out of range, non-finite numbers or points
// beyond 1000 m, empty lists, repeated nodes, a centre-line with fewer than 2 distinct points,
// more than max_target_count targets or max_centerline_points points. The file is at most
// max_json_file_bytes (io/input_file.hpp).
TargetsInput read_targets(const JsonInput& json, int node_count);
TargetsInput load_targets(const std::filesystem::path& file, int node_count);

// The "targets" list of TARGETS.json, [{"node": i, "position": [x, y, z]}, …]: how `solve`'s
// result and the GUI's state message show targets too.
nlohmann::json targets_json(const ShapeTargets& targets);

}  // namespace shapectl
