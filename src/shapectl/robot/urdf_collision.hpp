#pragma once
// The URDF collision geometry that RobotModel does not load: meshes (their files are found with
// resolve_mesh_file, mesh_resource.hpp).
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/robot/mesh_resource.hpp>  // resolve_mesh_file
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
// RobotModel::load_urdf_file accepted the same file and `xacro` (it bounds size, depth and
// counts).
std::vector<MeshCollision> read_mesh_collisions(const RobotModel& model,
                                                const std::filesystem::path& urdf_file,
                                                const XacroOptions& xacro = {});

}  // namespace shapectl
