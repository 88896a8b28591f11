// Obstacles on robot links and the robot's spheres as obstacles through the CLI (issue 34): the
// YuMi bar solves with them; a link the robot lacks, or robot contact without spheres, is bad
// input naming its field.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

nlohmann::json yumi_bar() {
  return nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
}

test::CliRun statics(const TempDir& dir, const nlohmann::json& scene) {
  const auto file = dir.write("scene.json", scene.dump(1));
  return run_cli({"statics", file.string(), "--out", (dir.path() / "result.json").string()});
}

TEST(LinkObstaclesCli, TheYumiBarSolvesWithARobotContactAndABoxOnALink) {
  TempDir dir;
  nlohmann::json scene = yumi_bar();
  scene["contact"] = {{"robot", true}};
  // A box on the left arm's fourth link, far from the bar: it moves with the arm, touching nothing.
  scene["obstacles"] = nlohmann::json::parse(
      R"([{"name": "pad", "link": "yumi_link_4_l", "box": {"size": [0.02, 0.02, 0.02]}}])");
  const test::CliRun run = statics(dir, scene);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(test::read_text(dir.path() / "result.json"));
  ASSERT_TRUE(result.contains("contacts")) << result.dump();
  EXPECT_TRUE(result["contacts"]["by_obstacle"].contains("pad"));
  EXPECT_TRUE(result["contacts"]["by_obstacle"].contains("gripper_l_finger_r sphere 1"));
}

TEST(LinkObstaclesCli, ALinkTheRobotLacksOrRobotContactWithoutSpheresIsBadInput) {
  TempDir dir;
  nlohmann::json scene = yumi_bar();
  scene["obstacles"] = nlohmann::json::parse(
      R"([{"link": "gripper_l", "sphere": {"center": [0, 0, 0.1], "radius": 0.01}}])");
  test::CliRun run = statics(dir, scene);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("scene.json: obstacles[0].link: "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("a link of the robot yumi.urdf"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("gripper_l_base"), std::string::npos) << run.err;  // the links listed

  scene["obstacles"] = nlohmann::json::parse(
      R"([{"link": "gripper_l_base", "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}])");
  run = statics(dir, scene);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("scene.json: obstacles[0].plane: "), std::string::npos) << run.err;

  scene.erase("obstacles");
  scene["contact"] = {{"robot", true}};
  scene["robot"].erase("collision_spheres");
  run = statics(dir, scene);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("scene.json: contact.robot: "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("collision_spheres"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace shapectl
