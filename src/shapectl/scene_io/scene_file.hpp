#pragma once
// SCENE.json → Scene (sim/scene.hpp): the strict scene reader. It sits above sim/ because it
// needs everything a scene names: mesh files (mesh/), the URDF and collision spheres (robot/)
// and the plausibility checks (sim/scene_checks.hpp). Paths are relative to the scene file.
#include <filesystem>

#include <Eigen/Geometry>

#include <shapectl/sim/scene.hpp>

namespace shapectl {

class JsonInput;

// Bounds on a scene's poses (read_pose): the position within max_scene_distance of the origin,
// roll, pitch and yaw each within ±max_scene_angle.
inline constexpr double max_scene_distance = 1e3;  // m
inline constexpr double max_scene_angle = 1e3;     // rad

// Reads and validates a scene, then runs check_scene (sim/scene_checks.hpp) on it: throws
// InputError naming the file and field for bad or implausible input, fills `warnings`.
// A mesh file may give "units" ("m", "cm", "mm") or "scale" (a factor): its nodes are scaled to
// metres before anything else (TetGen included) sees them.
Scene load_scene(const std::filesystem::path& file);

// Parsers shared by scene-like files.
AlignedBox read_box(const JsonInput& j);
NodeSelection read_node_selection(const JsonInput& j, int node_count);
// "loads": [{"nodes" and/or "box", "force"}], a force (N, world frame) shared equally by its
// nodes (rest positions, object coordinates). A load on no node is left for the caller to
// refuse (load_scene does after its checks; see refuse_empty_loads).
std::vector<NodeLoad> read_loads(const JsonInput& list, const TetMesh& mesh);
// Throws InputError naming "<list>[k].box" (or ".nodes") of the first load on no node.
void refuse_empty_loads(const JsonInput& list, const std::vector<NodeLoad>& loads);
// {"position": [x, y, z], "rpy": [roll, pitch, yaw]} (io/json_eigen.hpp: scene_pose_json).
Eigen::Isometry3d read_pose(const JsonInput& j);
// An "object.mesh" value (a file name, {"file", "units", ...} or {"box"}) as load_scene reads
// it: `shapectl author` numbers its grips' nodes as the scene will.
std::shared_ptr<const TetMesh> load_object_mesh(const JsonInput& j);
// "units" ("m", "cm", "mm") or "scale" of a mesh file: the factor from its coordinates to
// metres (1 without either).
double read_mesh_scale(const JsonInput& j);

}  // namespace shapectl
