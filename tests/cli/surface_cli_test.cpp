// `statics --surface` and `solve --surface`: the deformed surface as PLY or OBJ, read back here.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

const char* const kBarScene =
    test::kClampedBarScene;  // its surface: 2 × (8·2 + 8·2 + 2·2) quads, 2 triangles each
constexpr std::size_t kBarNodes = 81, kBarTriangles = 144;

struct Surface {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> faces;  // 0-based
};

Surface read_ply(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line, word;
  std::size_t vertices = 0, faces = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string element;
    words >> word >> element;
    if (word == "element" && element == "vertex") words >> vertices;
    if (word == "element" && element == "face") words >> faces;
  }
  Surface s;
  s.vertices.resize(vertices);
  for (auto& v : s.vertices) in >> v[0] >> v[1] >> v[2];
  s.faces.resize(faces);
  for (auto& f : s.faces) {
    int n = 0;
    in >> n >> f[0] >> f[1] >> f[2];
    EXPECT_EQ(n, 3);
  }
  EXPECT_TRUE(in) << file;
  return s;
}

Surface read_obj(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  Surface s;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string kind;
    words >> kind;
    if (kind == "v") {
      auto& v = s.vertices.emplace_back();
      words >> v[0] >> v[1] >> v[2];
    } else if (kind == "f") {
      auto& f = s.faces.emplace_back();
      words >> f[0] >> f[1] >> f[2];
      for (int& k : f) --k;  // OBJ counts from 1
    }
  }
  return s;
}

// Every vertex is the result's node position, exactly; every face indexes a vertex.
void expect_surface_of(const Surface& s, const nlohmann::json& positions) {
  ASSERT_EQ(s.vertices.size(), positions.size());
  for (std::size_t k = 0; k < s.vertices.size(); ++k)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(s.vertices[k][c], positions[k][c].get<double>()) << k;
  for (const auto& f : s.faces)
    for (int k : f) {
      EXPECT_GE(k, 0);
      EXPECT_LT(k, static_cast<int>(s.vertices.size()));
    }
}

TEST(SurfaceCli, StaticsWritesTheDeformedSurfaceAsPlyAndObj) {
  TempDir dir;
  const auto scene = dir.write("bar.json", kBarScene);
  for (const std::string name : {"bar.ply", "bar.obj"}) {
    const auto out = dir.path() / "result.json", surface = dir.path() / name;
    const auto run =
        run_cli({"statics", scene.string(), "--out", out.string(), "--surface", surface.string()});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto positions = nlohmann::json::parse(test::read_text(out))["positions"];
    const Surface s = name == "bar.ply" ? read_ply(surface) : read_obj(surface);
    EXPECT_EQ(s.vertices.size(), kBarNodes) << name;
    EXPECT_EQ(s.faces.size(), kBarTriangles) << name;
    expect_surface_of(s, positions);
    // The free end sags: the surface is the deformed one, not the rest shape.
    EXPECT_LT(s.vertices[8][2], -0.015 - 1e-4) << name;
  }
}

TEST(SurfaceCli, SolveWritesTheSurfaceAtTheBestJoints) {
  TempDir dir;
  const std::string bar = test::source_path("scenes/yumi_bar.json").string();
  const auto reference = dir.path() / "ref.json";
  ASSERT_EQ(run_cli({"statics", bar, "--out", reference.string()}).exit_code, 0);
  const auto start = nlohmann::json::parse(test::read_text(reference))["positions"];
  // Node 0 a centimetre higher.
  nlohmann::json goal = start[0];
  goal[2] = goal[2].get<double>() + 0.01;
  nlohmann::json targets_json;
  targets_json["targets"] = nlohmann::json::array({{{"node", 0}, {"position", goal}}});
  const auto targets = dir.write("targets.json", targets_json.dump());
  const auto out = dir.path() / "solve.json", surface = dir.path() / "bar.OBJ";
  const auto run = run_cli({"solve", bar, "--targets", targets.string(), "--out", out.string(),
                            "--surface", surface.string(), "--max-iterations", "20"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto positions = nlohmann::json::parse(test::read_text(out))["positions"];
  const Surface s = read_obj(surface);
  EXPECT_GT(s.faces.size(), 0u);
  expect_surface_of(s, positions);
  EXPECT_NE(positions[0], start[0]);
}

TEST(SurfaceCli, AnotherExtensionIsBadInputNamingTheOption) {
  TempDir dir;
  const auto scene = dir.write("bar.json", kBarScene);
  const auto out = dir.path() / "result.json";
  for (const std::string command : {"statics", "solve"}) {
    std::vector<std::string> args = {command,     scene.string(),
                                     "--out",     out.string(),
                                     "--surface", (dir.path() / "bar.stl").string()};
    if (command == "solve") args.insert(args.end(), {"--targets", scene.string()});
    const auto run = run_cli(args);
    EXPECT_EQ(run.exit_code, 1) << command;
    EXPECT_NE(run.err.find(command + ": --surface: expected a file name ending in .ply or .obj"),
              std::string::npos)
        << run.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << "checked before any work";
  }
}

}  // namespace
}  // namespace shapectl
