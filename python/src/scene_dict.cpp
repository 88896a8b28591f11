// Scene ↔ dict in the scene file's schema, through the same reader and writer as files
// (load_scene, scene_json_with_values): they take files, so the JSON goes through a private
// temporary file whose name messages then replace with "scene".
#include <cstdlib>
#include <fstream>
#include <functional>

#include <shapectl/io/input_file.hpp>
#include <shapectl/scene_io/scene_writer.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

const std::string dict_source = "scene";  // what messages call a scene given as a dict

// A JSON text in a file of its own (a fresh directory under TMPDIR), removed on destruction.
class TempJsonFile {
 public:
  explicit TempJsonFile(const std::string& text) {
    std::string name = (std::filesystem::temp_directory_path() / "shapectl-scene-XXXXXX").string();
    if (!mkdtemp(name.data()))
      throw std::runtime_error("cannot create a temporary directory in " +
                               std::filesystem::temp_directory_path().string());
    directory_ = name;
    if (!(std::ofstream(path()) << text))
      throw std::runtime_error("cannot write " + path().string());
  }
  ~TempJsonFile() {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
  }
  TempJsonFile(const TempJsonFile&) = delete;
  TempJsonFile& operator=(const TempJsonFile&) = delete;
  std::filesystem::path path() const { return directory_ / "scene.json"; }

 private:
  std::filesystem::path directory_;
};

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// The scene's file names (the keys scene_json_with_values rebases), each passed to `rewrite`.
template <class Json>
void for_each_path(Json& scene, const std::function<std::string(const std::string&)>& rewrite) {
  auto visit = [&](Json& parent, const char* key) {
    if (!parent.is_object()) return;
    const auto it = parent.find(key);
    if (it != parent.end() && it->is_string()) *it = rewrite(it->template get<std::string>());
  };
  if (scene.is_object() && scene.contains("object")) {
    Json& object = scene["object"];
    visit(object, "mesh");
    if (object.is_object() && object.contains("mesh")) visit(object["mesh"], "file");
  }
  if (scene.is_object() && scene.contains("robot")) {
    visit(scene["robot"], "urdf");
    visit(scene["robot"], "collision_spheres");
  }
}

}  // namespace

SceneHandle scene_handle(Scene scene, std::shared_ptr<const std::string> document) {
  SceneHandle handle;
  auto shared = std::make_shared<const Scene>(std::move(scene));
  if (shared->robot) handle.object = std::make_shared<const GrippedObject>(*shared);
  handle.scene = std::move(shared);
  handle.document = std::move(document);
  return handle;
}

SceneHandle scene_from_dict(const py::handle& d, const std::filesystem::path& base_dir) {
  if (!py::isinstance<py::dict>(d))
    throw InputError(dict_source, "", "a dict of the scene file's schema",
                     std::string(py::str(py::type::of(d))));
  nlohmann::json json = json_from(d, dict_source);
  // Kept absolute, so that to_dict and calibrate's scene need no base directory.
  const auto base = std::filesystem::absolute(base_dir).lexically_normal();
  for_each_path(json, [&](const std::string& p) { return (base / p).string(); });
  auto document = std::make_shared<const std::string>(json.dump());

  py::gil_scoped_release release;  // a mesh file may go through TetGen
  const TempJsonFile file(*document);
  const std::string temp_name = file.path().string();
  Scene scene;
  try {
    scene = load_scene(file.path());
  } catch (const InputError& e) {
    throw InputError(replaced(e.what(), temp_name, dict_source));
  }
  scene.source = dict_source;
  for (std::string& warning : scene.warnings) warning = replaced(warning, temp_name, dict_source);
  return scene_handle(std::move(scene), std::move(document));
}

py::object scene_to_dict(const SceneHandle& s,
                         const std::optional<std::filesystem::path>& base_dir) {
  nlohmann::ordered_json json;
  std::filesystem::path from_dir;
  {
    py::gil_scoped_release release;
    if (s.document) {  // paths already absolute
      const TempJsonFile file(*s.document);
      json = scene_json_with_values(file.path(), *s.scene, file.path());
    } else {
      json = scene_json_with_values(s.scene->source, *s.scene, s.scene->source);
      from_dir = std::filesystem::absolute(s.scene->source).parent_path();
    }
  }
  const auto to_dir = base_dir
                          ? std::filesystem::weakly_canonical(std::filesystem::absolute(*base_dir))
                          : std::filesystem::path();
  for_each_path(json, [&](const std::string& p) {
    const auto target = std::filesystem::weakly_canonical(from_dir / p);
    const auto relative = base_dir ? target.lexically_relative(to_dir) : std::filesystem::path();
    return (relative.empty() ? target : relative).string();
  });
  return py::module_::import("json").attr("loads")(json.dump());
}

}  // namespace shapectl::python
