// Commands given ROBOT.urdf.xacro: the expansion is what they load, bad xacro exits 1 with
// file:line.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::source_path;
using test::TempDir;

const std::string kUr5Xacro =
    source_path("data/robots/xacro/ur5/ur_description/urdf/ur5_robot.urdf.xacro").string();
const std::string kUr5Reference = source_path("data/robots/xacro/ur5/ur5_robot.urdf").string();
const std::string kPandaXacro =
    source_path("data/robots/xacro/panda/franka_description/robots/panda_arm_hand.urdf.xacro")
        .string();

nlohmann::json kinematics(const std::vector<std::string>& args, const TempDir& dir) {
  const auto out = dir.path() / "out.json";
  std::vector<std::string> command = {"kinematics"};
  command.insert(command.end(), args.begin(), args.end());
  command.insert(command.end(), {"--out", out.string()});
  const test::CliRun run = run_cli(command);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return run.exit_code == 0 ? nlohmann::json::parse(test::read_text(out)) : nlohmann::json();
}

TEST(XacroCli, KinematicsOfTheXacroEqualsThatOfTheReferenceUrdf) {
  const TempDir dir;
  const auto joints = dir.write("joints.json", R"({"joints": {"shoulder_pan_joint": 0.3,
    "shoulder_lift_joint": -1.1, "elbow_joint": 1.4, "wrist_1_joint": -0.6,
    "wrist_2_joint": 2.0, "wrist_3_joint": 0.9}})");
  const nlohmann::json ours = kinematics({kUr5Xacro, "--joints", joints.string()}, dir);
  const nlohmann::json reference = kinematics({kUr5Reference, "--joints", joints.string()}, dir);
  ASSERT_EQ(reference["links"].size(), 9u);
  for (const auto& [link, pose] : reference["links"].items())
    EXPECT_EQ(ours["links"][link], pose) << link;
  // The source version adds the ROS-Industrial base and tool0 frames (data/robots/xacro/README.md).
  EXPECT_EQ(ours["links"].size(), 11u);
  EXPECT_TRUE(ours["links"].contains("tool0"));
  EXPECT_EQ(ours["limit_violations"], reference["limit_violations"]);
}

TEST(XacroCli, XacroArgsAreGivenOnTheCommandLine) {
  const TempDir dir;
  const nlohmann::json left = kinematics({kPandaXacro, "--xacro-arg", "arm_id:=left"}, dir);
  EXPECT_TRUE(left["links"].contains("left_link7"));
  EXPECT_FALSE(left["links"].contains("panda_link7"));
  const test::CliRun bad = run_cli({"kinematics", kPandaXacro, "--xacro-arg", "arm_id=left",
                                    "--out", (dir.path() / "o.json").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("expected NAME:=VALUE"), std::string::npos) << bad.err;
}

TEST(XacroCli, BadXacroExitsOneNamingFileAndLine) {
  const TempDir dir;
  const auto xacro = dir.write("arm.urdf.xacro", R"(<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base"/>
  <link name="${prefix}upper"/>
</robot>
)");
  const test::CliRun run =
      run_cli({"kinematics", xacro.string(), "--out", (dir.path() / "out.json").string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find(xacro.string() +
                         ":4: bad expression ${prefix}: undefined property 'prefix'"),
            std::string::npos)
      << run.err;
}

TEST(XacroCli, AuthorAndScenesAcceptAXacroRobot) {
  const TempDir dir;
  const test::CliRun run =
      run_cli({"author", kUr5Xacro, "--box", "0.3,0.05,0.05", "--end-effectors", "tool=ee_link",
               "--allow-missing-meshes", "--object-pose", "0.9,0.2,0", "--out",
               (dir.path() / "scene.json").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto scene = nlohmann::json::parse(test::read_text(dir.path() / "scene.json"));
  EXPECT_NE(scene["robot"]["urdf"].get<std::string>().find("ur5_robot.urdf.xacro"),
            std::string::npos);
  // The scene names the xacro: loading it expands it again.
  const test::CliRun statics = run_cli({"statics", (dir.path() / "scene.json").string(), "--out",
                                        (dir.path() / "result.json").string()});
  EXPECT_EQ(statics.exit_code, 0) << statics.err;
}

}  // namespace
}  // namespace shapectl
