#include <shapectl/robot/visual_meshes.hpp>

#include <shapectl/io/ascii_case.hpp>
#include <shapectl/io/input_file.hpp>  // bounded_preview
#include <shapectl/robot/mesh_resource.hpp>

namespace shapectl {

const char* to_string(MeshFormat format) {
  switch (format) {
    case MeshFormat::Stl: return "stl";
    case MeshFormat::Obj: return "obj";
    case MeshFormat::Dae: return "dae";
  }
  return "stl";
}

std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".dae") return MeshFormat::Dae;
  return std::nullopt;
}

std::vector<VisualMesh> find_visual_meshes(
    const RobotModel& model, const std::vector<std::filesystem::path>& package_paths) {
  const std::filesystem::path urdf_directory = std::filesystem::path(model.source()).parent_path();
  std::vector<VisualMesh> meshes;
  for (int l = 0; l < model.link_count(); ++l) {
    const auto& shapes = model.links()[static_cast<std::size_t>(l)].visual_shapes;
    for (int s = 0; s < static_cast<int>(shapes.size()); ++s) {
      const Shape& shape = shapes[static_cast<std::size_t>(s)];
      if (shape.kind != Shape::Kind::Mesh) continue;
      VisualMesh mesh{l, s, std::nullopt, MeshFormat::Stl, ""};
      const auto file = resolve_mesh_file(shape.mesh_filename, urdf_directory, package_paths);
      const auto format = mesh_format_of(file ? *file : std::filesystem::path(shape.mesh_filename));
      std::error_code error;
      if (!file) {
        mesh.problem = shape.mesh_filename.rfind("package://", 0) == 0
                           ? "not found in any package path (give --package-path DIR, the "
                             "folder holding the package, or set ROS_PACKAGE_PATH)"
                           : "not found";
      } else if (!format) {
        mesh.problem = "is not STL, DAE or OBJ";
      } else if (std::filesystem::file_size(*file, error) > max_visual_mesh_bytes || error) {
        mesh.problem = "is larger than " + std::to_string(max_visual_mesh_bytes >> 20) + " MiB";
      } else {
        mesh.file = std::filesystem::absolute(*file);
        mesh.format = *format;
      }
      meshes.push_back(std::move(mesh));
    }
  }
  return meshes;
}

std::string visual_mesh_warning(const RobotModel& model, const VisualMesh& mesh) {
  const Link& link = model.links()[static_cast<std::size_t>(mesh.link)];
  const Shape& shape = link.visual_shapes[static_cast<std::size_t>(mesh.shape)];
  return model.source() + ": link '" + bounded_preview(link.name) + "': visual mesh '" +
         bounded_preview(shape.mesh_filename) + "' " + mesh.problem +
         ": the link is drawn without it";
}

}  // namespace shapectl
