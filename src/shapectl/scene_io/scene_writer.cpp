#include <shapectl/scene_io/scene_writer.hpp>

#include <shapectl/io/input_file.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/scene_io/scene_file.hpp>

namespace shapectl {

namespace {

// `path` as written in `from_dir`'s file, rewritten for a file in `to_dir`.
std::string rebased(const std::string& path, const std::filesystem::path& from_dir,
                    const std::filesystem::path& to_dir) {
  const std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  const auto target = std::filesystem::weakly_canonical(std::filesystem::absolute(from_dir / p));
  // A file named without a directory ("out.json") is in the current one.
  const std::filesystem::path to = to_dir.empty() ? std::filesystem::path(".") : to_dir;
  const auto relative =
      target.lexically_relative(std::filesystem::weakly_canonical(std::filesystem::absolute(to)));
  return relative.empty() ? target.string() : relative.string();
}

void rebase_member(nlohmann::ordered_json& object, const char* key,
                   const std::filesystem::path& from_dir, const std::filesystem::path& to_dir) {
  if (object.is_object() && object.contains(key) && object[key].is_string())
    object[key] = rebased(object[key].get<std::string>(), from_dir, to_dir);
}

// The object's pose as `object` (the file's) gives it; the identity without one.
Eigen::Isometry3d written_pose(const nlohmann::ordered_json& object,
                               const std::filesystem::path& source) {
  if (!object.contains("pose")) return Eigen::Isometry3d::Identity();
  return read_pose(JsonInput(nlohmann::json(object["pose"]), source.string(), "object.pose"));
}

}  // namespace

namespace {

// The material's values in the form the file gives them (mu and kappa, or E and ν).
void write_material(nlohmann::ordered_json& material, const Material& m) {
  if (material.contains("mu")) {
    material["mu"] = m.mu;
    material["kappa"] = m.kappa;
  } else {
    material["youngs_modulus"] = youngs_modulus_of(m);
    material["poisson_ratio"] = poisson_ratio_of(m);
  }
  material["density"] = m.density;
}

}  // namespace

nlohmann::ordered_json scene_json_with_values(const std::filesystem::path& source,
                                              const Scene& scene,
                                              const std::filesystem::path& out) {
  nlohmann::ordered_json j =
      nlohmann::ordered_json::parse(read_input_file(source, max_json_file_bytes, "JSON"));
  write_material(j["object"]["material"], scene.material);
  for (std::size_t k = 0; k < scene.regions.size(); ++k)
    write_material(j["regions"][k]["material"], scene.regions[k].material);
  // A pose the file gives stays as written unless it changed (rpy would round it).
  if (scene.T_world_object.matrix() != written_pose(j["object"], source).matrix())
    j["object"]["pose"] = scene_pose_json(scene.T_world_object);
  for (std::size_t k = 0; k < scene.grips.size(); ++k) {
    nlohmann::ordered_json& grip = j["grips"][k];
    if (scene.grips[k].offset.matrix() == Eigen::Matrix4d::Identity()) grip.erase("offset");
    else grip["offset"] = scene_pose_json(scene.grips[k].offset);
  }
  const auto from_dir = source.parent_path(), to_dir = out.parent_path();
  rebase_member(j["object"], "mesh", from_dir, to_dir);
  if (j["object"]["mesh"].is_object()) rebase_member(j["object"]["mesh"], "file", from_dir, to_dir);
  if (j.contains("obstacles") && j["obstacles"].is_array())
    for (auto& obstacle : j["obstacles"])
      if (obstacle.is_object() && obstacle.contains("mesh"))
        rebase_member(obstacle["mesh"], "file", from_dir, to_dir);
  if (j.contains("robot")) {
    rebase_member(j["robot"], "urdf", from_dir, to_dir);
    rebase_member(j["robot"], "collision_spheres", from_dir, to_dir);
  }
  return j;
}

}  // namespace shapectl
