#include <shapectl/robot/urdf_collision.hpp>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/robot_description.hpp>

namespace shapectl {

namespace {

// urdfdom logs through console_bridge; the project's loader already reported what matters.
class SilentLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string&, console_bridge::LogLevel, const char*, int) override {}
};

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Vec3(pose.position.x, pose.position.y, pose.position.z);
  double x = 0, y = 0, z = 0, w = 1;
  pose.rotation.getQuaternion(x, y, z, w);
  T.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  return T;
}

}  // namespace

std::vector<MeshCollision> read_mesh_collisions(const RobotModel& model,
                                                const std::filesystem::path& urdf_file,
                                                const XacroOptions& xacro) {
  const std::string xml = read_robot_description(urdf_file, xacro);
  SilentLog silent;
  console_bridge::useOutputHandler(&silent);
  urdf::ModelInterfaceSharedPtr urdf;
  try {
    urdf = urdf::parseURDF(xml);
  } catch (const std::exception&) {
  }
  console_bridge::restorePreviousOutputHandler();
  if (!urdf) throw InputError(urdf_file.string(), "", "not a valid URDF");
  std::vector<MeshCollision> meshes;
  for (int l = 0; l < model.link_count(); ++l) {
    const auto found = urdf->links_.find(model.links()[static_cast<std::size_t>(l)].name);
    if (found == urdf->links_.end() || !found->second) continue;
    for (const auto& collision : found->second->collision_array) {
      if (!collision || !collision->geometry || collision->geometry->type != urdf::Geometry::MESH)
        continue;
      const auto& mesh = static_cast<const urdf::Mesh&>(*collision->geometry);
      MeshCollision m{l, mesh.filename, Vec3(mesh.scale.x, mesh.scale.y, mesh.scale.z),
                      to_isometry(collision->origin)};
      if (!m.scale.allFinite() || !m.T_link_mesh.matrix().allFinite())
        throw InputError(urdf_file.string(),
                         "link '" + model.links()[static_cast<std::size_t>(l)].name + "'",
                         "mesh collision with non-finite scale or origin");
      meshes.push_back(std::move(m));
    }
  }
  return meshes;
}

}  // namespace shapectl
