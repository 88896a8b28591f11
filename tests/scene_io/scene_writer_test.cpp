#include <shapectl/scene_io/scene_writer.hpp>

#include <gtest/gtest.h>

#include <filesystem>

#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

// `calibrate --out calibrated.json` (no directory) once exited 3: the current directory was
// taken as an empty path.
TEST(SceneWriter, AnOutputNamedWithoutADirectoryRebasesPathsToTheCurrentOne) {
  const std::filesystem::path scene = test::source_path("scenes/yumi_cantilever.json");
  const nlohmann::ordered_json out =
      scene_json_with_values(scene, load_scene(scene), "calibrated.json");
  const std::filesystem::path urdf = out["robot"]["urdf"].get<std::string>();
  EXPECT_TRUE(std::filesystem::exists(urdf)) << urdf;  // relative to the current directory
}

}  // namespace
}  // namespace shapectl
