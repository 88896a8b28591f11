// shapectl kinematics: output contract and every class of bad input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::source_path;
using test::TempDir;

const std::string kYumi = source_path("data/robots/yumi/yumi.urdf").string();
const std::string kYumiSpheres = source_path("data/robots/yumi/yumi_spheres.json").string();

// Two links, one revolute joint; the link carries a ROS package mesh that is not there.
const char* const kArmUrdf = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <link name="upper">
    <visual><geometry><mesh filename="package://arm_description/meshes/upper.stl"/></geometry></visual>
  </link>
</robot>
)";

void expect_error(const std::vector<std::string>& args, const std::string& message) {
  const test::CliRun run = run_cli(args);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find(message), std::string::npos)
      << "stderr: " << run.err << "\nexpected: " << message;
}

TEST(KinematicsCli, WritesLinkPosesClearancesAndLimitViolations) {
  const TempDir dir;
  const auto joints = dir.write("joints.json", R"({"joints": {"yumi_joint_2_r": 1.0}})");
  const auto out = dir.path() / "out.json";
  const test::CliRun run = run_cli({"kinematics", kYumi, "--joints", joints.string(), "--spheres",
                                    kYumiSpheres, "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto json = nlohmann::json::parse(test::read_text(out));
  // All-zero left arm: the known flange pose of kinematics.md §6.3.
  const auto& flange = json["links"]["gripper_l_base"];
  EXPECT_NEAR(flange["position"][0].get<double>(), 0.56860, 1e-5);
  EXPECT_NEAR(flange["position"][1].get<double>(), -0.00497, 1e-5);
  EXPECT_NEAR(flange["position"][2].get<double>(), 0.51362, 1e-5);
  EXPECT_EQ(flange["rotation"].size(), 3u);
  EXPECT_EQ(json["links"]["world"]["position"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(json["links"].size(), 25u);
  EXPECT_TRUE(json["min_clearance"].is_number());
  EXPECT_EQ(json["margin"], 0.005);
  ASSERT_EQ(json["closest_pairs"].size(), 10u);
  EXPECT_EQ(json["closest_pairs"][0]["clearance"], json["min_clearance"]);
  EXPECT_EQ(json["closest_pairs"][0]["links"].size(), 2u);
  // 1.0 rad is beyond joint 2's upper limit of 43.5°.
  ASSERT_EQ(json["limit_violations"].size(), 1u);
  EXPECT_EQ(json["limit_violations"][0]["joint"], "yumi_joint_2_r");
  EXPECT_EQ(json["limit_violations"][0]["value"], 1.0);
}

TEST(KinematicsCli, AMissingMeshIsNamedInAWarning) {
  const TempDir dir;
  const auto urdf = dir.write("arm.urdf", kArmUrdf);
  const auto joints = dir.write("joints.json", R"({"joints": {"shoulder": 1.5707963267948966}})");
  const auto out = dir.path() / "out.json";
  const test::CliRun run =
      run_cli({"kinematics", urdf.string(), "--joints", joints.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("warning: " + urdf.string() +
                         ": link 'upper': visual mesh "
                         "'package://arm_description/meshes/upper.stl' not found in any package "
                         "path (give --package-path"),
            std::string::npos)
      << run.err;
  const auto json = nlohmann::json::parse(test::read_text(out));
  const auto& rotation = json["links"]["upper"]["rotation"];
  EXPECT_NEAR(rotation[0][1].get<double>(), -1.0, 1e-12);  // 90° about z
  EXPECT_NEAR(rotation[1][0].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(json["links"]["upper"]["position"], nlohmann::json({0.0, 0.0, 0.5}));
  ASSERT_EQ(json["limit_violations"].size(), 1u);  // 90° is past the 1 rad limit
  EXPECT_EQ(json["limit_violations"][0]["joint"], "shoulder");
  EXPECT_FALSE(json.contains("min_clearance"));
}

TEST(KinematicsCli, MissingFilesAreNamed) {
  const TempDir dir;
  const auto urdf = dir.write("arm.urdf", kArmUrdf);
  const std::string out = (dir.path() / "out.json").string();
  expect_error({"kinematics", (dir.path() / "nope.urdf").string(), "--out", out},
               (dir.path() / "nope.urdf").string() + ": cannot open file");
  expect_error({"kinematics", urdf.string(), "--joints", (dir.path() / "j.json").string(), "--out",
                out},
               (dir.path() / "j.json").string() + ": cannot open file");
  expect_error({"kinematics", urdf.string(), "--spheres", (dir.path() / "s.json").string(), "--out",
                out},
               (dir.path() / "s.json").string() + ": cannot open file");
}

TEST(KinematicsCli, UrdfErrorsNameTheFileAndTheElement) {
  const TempDir dir;
  const std::string out = (dir.path() / "out.json").string();
  const auto broken = dir.write("broken.urdf", "<robot name=\"x\"><link name=\"a\"></robot>");
  expect_error({"kinematics", broken.string(), "--out", out},
               broken.string() + ": not a valid URDF");

  std::string bad_limit = kArmUrdf;
  bad_limit.replace(bad_limit.find("lower=\"-1\""), 10, "lower=\"2.1\"");
  const auto limit = dir.write("limit.urdf", bad_limit);
  expect_error({"kinematics", limit.string(), "--out", out},
               limit.string() + ":4: joint 'shoulder': limit lower 2.1 > upper 1");

  std::string nan_origin = kArmUrdf;
  nan_origin.replace(nan_origin.find("xyz=\"0 0 0.5\""), 13, "xyz=\"0 0 nan\"");
  const auto nan = dir.write("nan.urdf", nan_origin);
  expect_error({"kinematics", nan.string(), "--out", out}, nan.string() + ": not a valid URDF");
}

TEST(KinematicsCli, KinematicLoopsAreRejected) {
  const TempDir dir;
  const std::string out = (dir.path() / "out.json").string();
  std::string two_parents = kArmUrdf;
  two_parents.replace(two_parents.find("</robot>"), 8, R"(  <joint name="elbow" type="fixed">
    <parent link="base"/><child link="upper"/>
  </joint>
</robot>)");
  const auto loop = dir.write("loop.urdf", two_parents);
  expect_error({"kinematics", loop.string(), "--out", out},
               "(kinematic loop; URDF must be a tree)");
  expect_error({"kinematics", loop.string(), "--out", out}, "already has parent joint");

  std::string detached_cycle = kArmUrdf;
  detached_cycle.replace(detached_cycle.find("</robot>"), 8, R"(  <link name="p"/><link name="q"/>
  <joint name="pq" type="fixed"><parent link="p"/><child link="q"/></joint>
  <joint name="qp" type="fixed"><parent link="q"/><child link="p"/></joint>
</robot>)");
  const auto cycle = dir.write("cycle.urdf", detached_cycle);
  expect_error({"kinematics", cycle.string(), "--out", out},
               "not reachable from the root link 'base'");
}

TEST(KinematicsCli, JointFileErrorsNameTheFileAndTheJoint) {
  const TempDir dir;
  const auto urdf = dir.write("arm.urdf", kArmUrdf);
  const std::string out = (dir.path() / "out.json").string();
  const auto unknown = dir.write("unknown.json", R"({"joints": {"elbow": 0.1}})");
  expect_error({"kinematics", urdf.string(), "--joints", unknown.string(), "--out", out},
               unknown.string() + ": joints.elbow: unknown joint in " + urdf.string());
  const auto huge = dir.write("huge.json", R"({"joints": {"shoulder": 1e999}})");
  expect_error({"kinematics", urdf.string(), "--joints", huge.string(), "--out", out},
               huge.string() + ": joints.shoulder: expected a finite number");  // 1e999 overflows
  const auto typo = dir.write("typo.json", R"({"joint": {"shoulder": 0.1}})");
  expect_error({"kinematics", urdf.string(), "--joints", typo.string(), "--out", out},
               typo.string() + ": joint: unknown key; known: joints");
}

// Issue 36: a result of statics (or solve, or run) is a joints file, its fixed joints (the
// gripper's fingers) included, so kinematics on the bare URDF gives the pose it was computed at.
TEST(KinematicsCli, AResultGivesItsPoseFingersIncluded) {
  const TempDir dir;
  const std::string bar = source_path("scenes/yumi_bar.json").string();
  const auto joints =
      dir.write("joints.json", R"({"joints": {"yumi_joint_1_l": 0.1, "yumi_joint_6_r": -0.2}})");
  const auto result_file = dir.path() / "result.json";
  const test::CliRun statics =
      run_cli({"statics", bar, "--joints", joints.string(), "--out", result_file.string()});
  ASSERT_EQ(statics.exit_code, 0) << statics.err;
  nlohmann::json result = nlohmann::json::parse(test::read_text(result_file));
  EXPECT_EQ(result["fixed_joints"],
            nlohmann::json({{"gripper_l_joint", 0.015}, {"gripper_r_joint", 0.015}}));
  auto links_at = [&](const std::filesystem::path& file) {
    const auto out = dir.path() / "links.json";
    const test::CliRun run =
        run_cli({"kinematics", kYumi, "--joints", file.string(), "--out", out.string()});
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(test::read_text(out))["links"];
  };
  const nlohmann::json from_result = links_at(result_file);
  // The same as every joint written out by hand, the fingers at the scene's 15 mm.
  nlohmann::json all = result["joints"];
  all.update(result["fixed_joints"]);
  EXPECT_EQ(from_result, links_at(dir.write("all.json", nlohmann::json{{"joints", all}}.dump())));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(from_result["gripper_l_tcp"]["position"][k].get<double>(),
                result["tools"]["left"]["position"][k].get<double>(), 1e-12);
    EXPECT_NEAR(from_result["gripper_r_tcp"]["position"][k].get<double>(),
                result["tools"]["right"]["position"][k].get<double>(), 1e-12);
  }
  // Without them the fingers would be closed: the result's fixed joints are what reproduces it.
  result.erase("fixed_joints");
  EXPECT_NE(links_at(dir.write("closed.json", result.dump()))["gripper_l_finger_r"]["position"],
            from_result["gripper_l_finger_r"]["position"]);
  // A scene holding the fingers elsewhere cannot reproduce the result: refused, not ignored.
  result["fixed_joints"] = {{"gripper_l_joint", 0.02}};
  const auto other = dir.write("other.json", result.dump());
  expect_error({"statics", bar, "--joints", other.string(), "--out", result_file.string()},
               other.string() +
                   ": fixed_joints.gripper_l_joint: expected 0.015, the value this robot holds "
                   "the joint at (the result was computed with another), got 0.02");
}

TEST(KinematicsCli, SphereFileErrorsNameTheFileAndTheLink) {
  const TempDir dir;
  const std::string out = (dir.path() / "out.json").string();
  const auto spheres = dir.write("spheres.json", R"({"spheres": {"yumi_link_9_l": []}})");
  expect_error({"kinematics", kYumi, "--spheres", spheres.string(), "--out", out},
               spheres.string() + ": spheres.yumi_link_9_l: unknown link 'yumi_link_9_l'");
  const auto ignore =
      dir.write("ignore.json", R"({"spheres": {}, "ignore_pairs": [["yumi_body"]]})");
  expect_error({"kinematics", kYumi, "--spheres", ignore.string(), "--out", out},
               ignore.string() + ": ignore_pairs[0]: expected a pair of link names");
}

// Issue 10: a name with an invalid UTF-8 byte made the JSON writer throw (exit 3) after the old
// result was truncated. Now the byte is written as U+FFFD and the result replaces the old one
// only once complete.
TEST(KinematicsCli, InvalidUtf8InALinkNameIsWrittenNotThrown) {
  const TempDir dir;
  std::string text = kArmUrdf;
  text.replace(text.find("name=\"upper\""), 12, "name=\"upp\xff\xfer\"");
  text.replace(text.find("child link=\"upper\""), 18, "child link=\"upp\xff\xfer\"");
  const auto urdf = dir.write("utf.urdf", text);
  const auto out = dir.write("out.json", "precious");
  const test::CliRun run = run_cli({"kinematics", urdf.string(), "--out", out.string()});
  ASSERT_NE(run.exit_code, 3) << run.err;
  if (run.exit_code == 0) {
    const auto json = nlohmann::json::parse(test::read_text(out));
    EXPECT_TRUE(json["links"].contains("upp\xef\xbf\xbd\xef\xbf\xbdr")) << json.dump();
  } else {
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_EQ(test::read_text(out), "precious");
  }
}

TEST(KinematicsCli, OutThatIsADirectoryIsNamed) {
  const TempDir dir;
  dir.write("out.json/keep.txt", "kept");
  const auto out = dir.path() / "out.json";
  expect_error({"kinematics", kYumi, "--out", out.string()},
               out.string() + ": cannot write: it is a directory");
  EXPECT_EQ(test::read_text(out / "keep.txt"), "kept");
}

}  // namespace
}  // namespace shapectl
