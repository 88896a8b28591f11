#pragma once
// The files of a robot's visual meshes (Shape::Kind::Mesh): found through mesh_resource.hpp,
// with their format, or why one cannot be drawn. The GUI serves exactly these files; every
// command warns about the others.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

inline constexpr std::uintmax_t max_visual_mesh_bytes = 64u << 20;  // YuMi's largest is 2 MB

enum class MeshFormat { Stl, Obj, Dae };
const char* to_string(MeshFormat format);  // "stl", "obj", "dae": also the URL's extension
// By the file's extension, in any case; nullopt for anything else.
std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& file);

struct VisualMesh {
  int link = -1;  // model.links()[link].visual_shapes[shape]
  int shape = -1;
  std::optional<std::filesystem::path> file;  // set only when it can be drawn
  MeshFormat format = MeshFormat::Stl;
  std::string problem;  // why `file` is unset: "not found ...", "is not STL, DAE or OBJ", ...
};

// Every visual mesh of `model`, links in order, visuals in file order. Relative and file://
// names resolve against the directory of model.source() (the URDF file).
std::vector<VisualMesh> find_visual_meshes(const RobotModel& model,
                                           const std::vector<std::filesystem::path>& package_paths);

// "<urdf>: link 'l': visual mesh 'package://p/a.stl' not found (...): the link is drawn without
// it" for a mesh with a problem.
std::string visual_mesh_warning(const RobotModel& model, const VisualMesh& mesh);

}  // namespace shapectl
