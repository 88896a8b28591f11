// Issue 36 item 13: a mistyped command is answered with the nearest one; a missing file's
// message says how its path was resolved (relative to the current directory or to the folder of
// the scene that names it).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

std::string error_of(const std::vector<std::string>& args,
                     const std::filesystem::path& working_directory = {}) {
  const test::CliRun run = run_cli(args, working_directory);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  return run.err;
}

TEST(MistakesCli, AMistypedCommandSuggestsTheNearest) {
  for (const auto& [typed, meant] :
       std::vector<std::pair<std::string, std::string>>{{"solv", "solve"},
                                                        {"statcs", "statics"},
                                                        {"kin", "kinematics"},
                                                        {"egmsim", "egm-sim"},
                                                        {"calibrat", "calibrate"}}) {
    const std::string err = error_of({typed, "scene.json", "--out", "out.json"});
    EXPECT_NE(err.find("error: unknown command '" + typed + "'; did you mean '" + meant + "'?"),
              std::string::npos)
        << err;
  }
  // Nothing near: no guess, the list of commands.
  const std::string err = error_of({"frobnicate"});
  EXPECT_EQ(err.find("did you mean"), std::string::npos) << err;
  EXPECT_NE(err.find("unknown command 'frobnicate' (commands: statics, kinematics, author, solve"),
            std::string::npos)
      << err;
  // Known commands and options are CLI11's as before.
  EXPECT_EQ(run_cli({"--version"}).exit_code, 0);
  EXPECT_EQ(error_of({"solve"}).find("unknown command"), std::string::npos);
}

TEST(MistakesCli, AMissingFileNamedOnTheCommandLineSaysWhereItWasLooked) {
  const TempDir dir;
  const auto here = std::filesystem::canonical(dir.path());  // what getcwd() reports
  std::filesystem::create_directories(here / "work");
  const auto out = (here / "out.json").string();
  EXPECT_NE(error_of({"statics", "none.json", "--out", out}, here / "work")
                .find("none.json: cannot open file (No such file or directory; relative to the "
                      "current directory " +
                      (here / "work").string() + ": " + (here / "work" / "none.json").string() +
                      ")"),
            std::string::npos);
  EXPECT_NE(error_of({"statics", "../none.json", "--out", out}, here / "work")
                .find("../none.json: cannot open file (No such file or directory; relative to the "
                      "current directory " +
                      (here / "work").string() + ": " + (here / "none.json").string() + ")"),
            std::string::npos);
  // An absolute path is where it says.
  const std::string absolute = (here / "none.json").string();
  const std::string err = error_of({"statics", absolute, "--out", out});
  EXPECT_NE(err.find(absolute + ": cannot open file (No such file or directory)"),
            std::string::npos)
      << err;
}

TEST(MistakesCli, AMissingFileNamedInASceneSaysItIsRelativeToTheScenesFolder) {
  const TempDir dir;
  const auto here = std::filesystem::canonical(dir.path());
  auto scene = nlohmann::json::parse(test::kClampedBarScene);
  scene["object"]["mesh"] = "../meshes/bar.msh";
  dir.write("scenes/bar.json", scene.dump());
  const std::string out = (here / "out.json").string();
  const std::string err = error_of({"statics", "scenes/bar.json", "--out", out}, here);
  EXPECT_NE(err.find("scenes/bar.json: object.mesh: no file '../meshes/bar.msh' (relative to the "
                     "folder of scenes/bar.json, " +
                     (here / "scenes").string() + ": " + (here / "meshes" / "bar.msh").string() +
                     ")"),
            std::string::npos)
      << err;
  // The same for the robot's files.
  auto robot_scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  robot_scene["robot"]["urdf"] = "arm.urdf";
  const auto file = dir.write("robot.json", robot_scene.dump());
  const std::string urdf_err = error_of({"statics", file.string(), "--out", out});
  EXPECT_NE(urdf_err.find(file.string() +
                          ": robot.urdf: no file 'arm.urdf' (relative to the "
                          "folder of " +
                          file.string() + ", " + dir.path().string() + ": " +
                          (dir.path() / "arm.urdf").string() + ")"),
            std::string::npos)
      << urdf_err;
}

}  // namespace
}  // namespace shapectl
