// `author --approach/--grip-axis/--tool-axes` (issue 36 item 8): the grasp orientation asked
// for is the one the written scene's reference joints give the tools, on the bundled YuMi.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using Json = nlohmann::json;
using test::run_cli;
using test::TempDir;

// The YuMi bar's placement (scenes/yumi_bar.json) with its grips at the bar's ends.
std::vector<std::string> yumi_author(const TempDir& dir, std::vector<std::string> extra) {
  std::vector<std::string> args = {"author",
                                   test::source_path("data/robots/yumi/yumi.urdf").string(),
                                   "--box",
                                   "0.32,0.03,0.03",
                                   "--end-effectors",
                                   "left=gripper_l_tcp,right=gripper_r_tcp",
                                   "--object-pose",
                                   "0.39047,0,0.25527,0,0,1.5707963",
                                   "--grip-region",
                                   "left=0.139,-0.02,-0.02,0.161,0.02,0.02",
                                   "--grip-region",
                                   "right=-0.161,-0.02,-0.02,-0.139,0.02,0.02",
                                   "--allow-missing-meshes",
                                   "--out",
                                   (dir.path() / "scene.json").string(),
                                   "--report",
                                   (dir.path() / "report.json").string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// Column `axis` of a link's rotation in a `kinematics` result at the scene's reference joints.
std::array<double, 3> tool_axis(const TempDir& dir, const std::string& link, int axis) {
  const Json scene = Json::parse(test::read_text(dir.path() / "scene.json"));
  const auto joints =
      dir.write("joints.json", Json{{"joints", scene["robot"]["reference_joints"]}}.dump());
  const auto out = dir.path() / "links.json";
  const auto run = run_cli({"kinematics", test::source_path("data/robots/yumi/yumi.urdf").string(),
                            "--joints", joints.string(), "--out", out.string()});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const Json links = Json::parse(test::read_text(out))["links"];
  const Json& R = links[link]["rotation"];
  return {R[0][axis].get<double>(), R[1][axis].get<double>(), R[2][axis].get<double>()};
}

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

TEST(AuthorGraspCli, TheToolsApproachFromTheDirectionAskedFor) {
  TempDir dir;
  const auto run =
      run_cli(yumi_author(dir, {"--approach", "left=0,0,-1", "--approach", "right=0,0,-1"}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* link : {"gripper_l_tcp", "gripper_r_tcp"})
    EXPECT_GT(dot(tool_axis(dir, link, 2), {0, 0, -1}), std::cos(2e-3)) << link;  // tool z down
}

// Both directions fix the grasp: the fingers (YuMi's close along the tool's x, found from the
// finger joint's axis) close across the bar's thin side.
TEST(AuthorGraspCli, ApproachAndGripAxisSetTheWholeGrasp) {
  TempDir dir;
  const auto run =
      run_cli(yumi_author(dir, {"--approach", "left=0,0,-1", "--grip-axis", "left=1,0,0",
                                "--approach", "right=0,0,-1", "--grip-axis", "right=-1,0,0"}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* link : {"gripper_l_tcp", "gripper_r_tcp"}) {
    EXPECT_GT(dot(tool_axis(dir, link, 2), {0, 0, -1}), std::cos(2e-3)) << link;
    EXPECT_GT(std::abs(dot(tool_axis(dir, link, 0), {1, 0, 0})), std::cos(2e-3)) << link;
  }
  const Json report = Json::parse(test::read_text(dir.path() / "report.json"));
  for (const auto& grip : report["grips"]) {
    EXPECT_NEAR(grip["approach_axis"][2].get<double>(), -1, 1e-5);
    EXPECT_NEAR(std::abs(grip["closing_axis"][0].get<double>()), 1, 1e-5);
  }
  // --tool-axes names other link axes: the tool's y now closes along the world x.
  TempDir other;
  const auto turned = run_cli(yumi_author(other, {"--approach", "left=0,0,-1", "--grip-axis",
                                                  "left=1,0,0", "--tool-axes", "left=z,y"}));
  ASSERT_EQ(turned.exit_code, 0) << turned.err;
  EXPECT_GT(std::abs(dot(tool_axis(other, "gripper_l_tcp", 1), {1, 0, 0})), std::cos(2e-3));
}

TEST(AuthorGraspCli, BadGraspOptionsAreExitOneNamingTheOption) {
  for (const auto& [extra, option] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--approach", "left=0,0,0"}, "--approach"},
           {{"--approach", "middle=0,0,-1"}, "--approach"},
           {{"--approach", "left=0,0"}, "--approach"},
           {{"--grip-axis", "left=x"}, "--grip-axis"},
           {{"--approach", "left=0,0,-1", "--grip-axis", "left=0,0.05,1"}, "--approach"},
           {{"--tool-axes", "left=z,z"}, "--tool-axes"},
           {{"--tool-axes", "left=z,w"}, "--tool-axes"},
           {{"--tool-axes", "left=z"}, "--tool-axes"}}) {
    TempDir dir;
    const auto run = run_cli(yumi_author(dir, extra));
    EXPECT_EQ(run.exit_code, 1) << option << "\n" << run.err;
    EXPECT_NE(run.err.find("command line: " + option + ": "), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "scene.json"));
  }
}

}  // namespace
}  // namespace shapectl
