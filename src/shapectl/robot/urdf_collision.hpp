#pragma once
// The URDF collision geometry that RobotModel does not load: meshes, with their file names
// resolved the way ROS does (relative to the URDF, file://, package:// through package paths).
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/robot/robot_model.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

struct MeshCollision {
  int link = -1;              // index into model.links()
  std::string filename;       // as written in the URDF
  Vec3 scale = Vec3::Ones();  // per axis, applied before the pose
  Eigen::Isometry3d T_link_mesh = Eigen::Isometry3d::Identity();
};

// Every <collision><geometry><mesh> of `urdf_file`, in link order. Call only after
// RobotModel::load_urdf_file accepted the same file (it bounds size, depth and counts).
std::vector<MeshCollision> read_mesh_collisions(const RobotModel& model,
                                                const std::filesystem::path& urdf_file);

// The file a URDF mesh name refers to, if it exists: "package://pkg/rest" is searched as
// <dir>/pkg/rest and <dir>/rest for each package path (the ROS convention), "file:///abs" is
// taken as is, a plain name is relative to the URDF's directory.
std::optional<std::filesystem::path> resolve_mesh_file(
    const std::string& filename, const std::filesystem::path& urdf_directory,
    const std::vector<std::filesystem::path>& package_paths);

}  // namespace shapectl
