#include <shapectl/calib/observations.hpp>

#include <gtest/gtest.h>

#include <string>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::input_error_of;
using test::TempDir;

// Two revolute joints and a gripper finger that is not active.
RobotModel two_joint_robot() {
  RobotModel robot = RobotModel::from_urdf_string(
      "<robot name='arm'><link name='base'/>"
      "<joint name='a1' type='revolute'><parent link='base'/><child link='l1'/><axis xyz='0 0 1'/>"
      "<limit lower='-2' upper='2' velocity='1' effort='1'/></joint><link name='l1'/>"
      "<joint name='a2' type='revolute'><parent link='l1'/><child link='l2'/><origin xyz='0.3 0 "
      "0'/>"
      "<axis xyz='0 1 0'/><limit lower='-2' upper='2' velocity='1' effort='1'/></joint><link "
      "name='l2'/>"
      "<joint name='finger' type='prismatic'><parent link='l2'/><child link='f'/><axis xyz='1 0 "
      "0'/>"
      "<limit lower='0' upper='0.02' velocity='1' effort='1'/></joint><link name='f'/></robot>",
      "arm.urdf");
  robot.set_active_joints({"a1", "a2"});
  return robot;
}

Observations parse(const std::string& text, const ObservationContext& context) {
  return read_observations(JsonInput(parse_json_text(text, "obs.json"), "obs.json"), context);
}

std::string error_of(const std::string& text, const ObservationContext& context) {
  return input_error_of([&] { parse(text, context); });
}

TEST(Observations, FileWithJointsMarkersInlinePointsAndAPointsFile) {
  const RobotModel robot = two_joint_robot();
  TempDir dir;
  dir.write("clouds/c0.xyz", "0.1 0.2 0.3\n0.4 0.5 0.6 extra\n");
  const auto file = dir.write("obs.json", R"({"frames": [
      {"joints": {"a2": -0.5, "a1": 0.25}, "markers": [{"node": 7, "position": [1, 2, 3]},
       {"node": 0, "position": [0, 0, 0.5]}], "sigma": 0.0005, "time": 12.5},
      {"joints": {"a1": 0, "a2": 1}, "points": [[0.1, 0, 0]], "markers": []},
      {"joints": {"a1": 0, "a2": 1}, "points_file": "clouds/c0.xyz"}]})");
  const Observations obs = load_observations(file, {.node_count = 8, .robot = &robot});
  ASSERT_EQ(obs.frames.size(), 3u);
  const ObservationFrame& f0 = obs.frames[0];
  EXPECT_EQ(f0.joints, Eigen::Vector2d(0.25, -0.5));
  ASSERT_EQ(f0.markers.size(), 2u);
  EXPECT_EQ(f0.markers[0].node, 7);
  EXPECT_EQ(f0.markers[0].position, Vec3(1, 2, 3));
  EXPECT_EQ(f0.markers[1].node, 0);
  EXPECT_TRUE(f0.points.empty());
  EXPECT_EQ(f0.sigma, 0.0005);
  EXPECT_EQ(f0.time, 12.5);
  const ObservationFrame& f1 = obs.frames[1];
  EXPECT_EQ(f1.points, std::vector<Vec3>{Vec3(0.1, 0, 0)});
  EXPECT_EQ(f1.sigma, default_observation_sigma);
  EXPECT_FALSE(f1.time.has_value());
  EXPECT_EQ(obs.frames[2].points, (std::vector<Vec3>{Vec3(0.1, 0.2, 0.3), Vec3(0.4, 0.5, 0.6)}));
}

TEST(Observations, SceneWithoutRobotHasNoJoints) {
  const Observations obs =
      parse(R"({"frames": [{"markers": [{"node": 1, "position": [0, 0, 0]}]}]})",
            {.node_count = 2});
  EXPECT_EQ(obs.frames.at(0).joints.size(), 0);
  // Issue 35: "joints": {} says the same as no key.
  EXPECT_EQ(parse(R"({"frames": [{"joints": {}, "points": [[0, 0, 0]]}]})", {.node_count = 2})
                .frames.at(0)
                .joints.size(),
            0);
  EXPECT_EQ(error_of(R"({"frames": [{"joints": {"a1": 0}, "points": [[0, 0, 0]]}]})",
                     {.node_count = 2}),
            "obs.json: frames[0].joints: the scene has no robot: expected no joints (or {})");
  EXPECT_EQ(error_of(R"({"frames": [{"joints": [], "points": [[0, 0, 0]]}]})", {.node_count = 2}),
            "obs.json: frames[0].joints: the scene has no robot: expected no joints (or {})");
}

TEST(Observations, BadFramesAreErrorsNamingTheField) {
  const RobotModel robot = two_joint_robot();
  const ObservationContext context{.node_count = 8, .robot = &robot};
  // A valid frame's joints, spliced into each case.
  const std::string j = R"("joints": {"a1": 0, "a2": 0})";
  auto frame = [&](const std::string& rest) {
    return R"({"frames": [{)" + j + ", " + rest + "}]}";
  };
  const std::string marker = R"("markers": [{"node": 1, "position": [0, 0, 0]}])";
  EXPECT_NO_THROW(parse(frame(marker), context));
  EXPECT_EQ(error_of(R"({"frames": []})", context),
            "obs.json: frames: expected a non-empty list of frames, got []");
  EXPECT_EQ(error_of(R"({"frame": []})", context),
            "obs.json: frame: unknown key; known: frames, priors, bounds");
  EXPECT_EQ(error_of(frame(R"("markers": [])"), context),
            "obs.json: frames[0]: nothing observed; expected at least one marker or one point");
  EXPECT_EQ(error_of(frame(R"("markers": [{"node": 8, "position": [0, 0, 0]}])"), context),
            "obs.json: frames[0].markers[0].node: expected a whole number from 0 to 7, got 8");
  EXPECT_EQ(
      error_of(
          frame(
              R"("markers": [{"node": 1, "position": [0, 0, 0]}, {"node": 1, "position": [1, 0, 0]}])"),
          context),
      "obs.json: frames[0].markers[1].node: expected a node without another marker in this frame, "
      "got 1");
  EXPECT_EQ(error_of(frame(R"("markers": [{"node": 1, "position": [0, "a", 0]}])"), context),
            "obs.json: frames[0].markers[0].position[1]: expected a number, got \"a\"");
  EXPECT_EQ(
      error_of(frame(R"("points": [[0, 0, 0], [5000, 0, 0]])"), context),
      "obs.json: frames[0].points[1]: expected a point of length at most 1000 m, got [5000,0,0]");
  EXPECT_EQ(error_of(frame(marker + R"(, "colour": 1)"), context),
            "obs.json: frames[0].colour: unknown key; known: joints, markers, points, points_file, "
            "depth_image, sigma, time, loads, object_pose");
  EXPECT_EQ(error_of(frame(marker + R"(, "sigma": 0)"), context),
            "obs.json: frames[0].sigma: expected a positive number, got 0");
  EXPECT_EQ(error_of(frame(marker + R"(, "time": -1)"), context),
            "obs.json: frames[0].time: expected a non-negative number, got -1");
  EXPECT_EQ(error_of(frame(R"("points": [[0, 0, 0]], "points_file": "c.xyz")"), context),
            "obs.json: frames[0]: more than one of \"points\", \"points_file\" and "
            "\"depth_image\"; expected one");
  EXPECT_EQ(error_of(frame(R"("points_file": "c.xyz")"), context),
            "obs.json: frames[0].points_file: point cloud files are read only from an observations "
            "file; expected \"points\"");
}

// Issue 35: a frame's own loads, read as the scene's (nodes or a box of rest positions, a force
// in N shared by them), replace the scene's; their errors name the frame and the field.
TEST(Observations, FramesCarryTheirOwnLoadsAndPoseCheckedAsTheScenesAre) {
  const TetMesh mesh = make_box_mesh({0.2, 0.02, 0.02}, {4, 1, 1});  // 20 nodes, x in ±0.1
  const ObservationContext context{.node_count = mesh.node_count(), .mesh = &mesh};
  auto frame = [](const std::string& loads) {
    return R"({"frames": [{"markers": [{"node": 1, "position": [0, 0, 0]}]},
        {"markers": [{"node": 1, "position": [0, 0, 0]}], "loads": )" +
           loads + "}]}";
  };
  const Observations obs = parse(frame(R"([{"box": {"min": [0.09, -1, -1], "max": [1, 1, 1]},
      "force": [0, 0, -0.5]}, {"nodes": [0, 3], "force": [0.1, 0, 0]}])"),
                                 context);
  ASSERT_EQ(obs.frames.size(), 2u);
  EXPECT_FALSE(obs.frames[0].loads.has_value());  // the scene's loads
  ASSERT_TRUE(obs.frames[1].loads.has_value());
  ASSERT_EQ(obs.frames[1].loads->size(), 2u);
  EXPECT_EQ((*obs.frames[1].loads)[0].nodes.size(), 4u);  // the free end's face
  EXPECT_EQ((*obs.frames[1].loads)[0].force, Vec3(0, 0, -0.5));
  EXPECT_EQ((*obs.frames[1].loads)[1].nodes, (std::vector<int>{0, 3}));
  EXPECT_TRUE(parse(frame("[]"), context).frames[1].loads->empty());  // none in this frame

  EXPECT_EQ(error_of(frame(R"([{"nodes": [1], "force": [0, "a", 0]}])"), context),
            "obs.json: frames[1].loads[0].force[1]: expected a number, got \"a\"");
  EXPECT_EQ(error_of(frame(R"([{"nodes": [20], "force": [0, 0, -1]}])"), context),
            "obs.json: frames[1].loads[0].nodes[0]: expected a whole number from 0 to 19, got 20");
  EXPECT_EQ(error_of(frame(
                         R"([{"box": {"min": [5, 5, 5], "max": [6, 6, 6]}, "force": [0, 0, 1]}])"),
                     context),
            "obs.json: frames[1].loads[0].box: expected a box around at least one node (rest "
            "positions, object coordinates), got {\"max\":[6,6,6],\"min\":[5,5,5]}");
  EXPECT_EQ(error_of(frame(R"([{"nodes": [1], "force": [0, 0, -1], "mass": 1}])"), context),
            "obs.json: frames[1].loads[0].mass: unknown key; known: nodes, box, force");
  EXPECT_EQ(error_of(frame(R"({"nodes": [1]})"), context),
            "obs.json: frames[1].loads: expected a list of loads [{\"nodes\" or \"box\", "
            "\"force\"}], got {\"nodes\":[1]}");
  // A frame's pose of the object (its clamp), as the scene's object.pose.
  const std::string posed = R"({"frames": [{"markers": [{"node": 1, "position": [0, 0, 0]}],
      "object_pose": {"position": [0.1, 0, 0.2], "rpy": [1.5707963267948966, 0, 0]}}]})";
  const Observations with_pose = parse(posed, context);
  ASSERT_TRUE(with_pose.frames[0].object_pose.has_value());
  EXPECT_TRUE(with_pose.frames[0].object_pose->translation().isApprox(Vec3(0.1, 0, 0.2)));
  EXPECT_TRUE(
      (with_pose.frames[0].object_pose->linear() * Vec3::UnitY()).isApprox(Vec3::UnitZ(), 1e-12));
  EXPECT_NE(error_of(R"({"frames": [{"markers": [{"node": 1, "position": [0, 0, 0]}],
      "object_pose": {"position": [0, 0], "rpy": [0, 0, 0]}}]})",
                     context)
                .find("obs.json: frames[0].object_pose.position"),
            std::string::npos);
  // Without the mesh (a frame from a network message) there is nothing to select nodes of.
  EXPECT_EQ(error_of(frame("[]"), {.node_count = 20}),
            "obs.json: frames[1].loads: per-frame conditions are read only from an observations "
            "file (or Python), not from a live channel");
}

TEST(Observations, JointsMustNameEveryActiveJointAndNoOther) {
  const RobotModel robot = two_joint_robot();
  const ObservationContext context{.node_count = 8, .robot = &robot};
  auto with_joints = [](const std::string& joints) {
    return R"({"frames": [{"points": [[0, 0, 0]], "joints": )" + joints + "}]}";
  };
  EXPECT_EQ(error_of(R"({"frames": [{"points": [[0, 0, 0]]}]})", context),
            "obs.json: frames[0].joints: missing key");
  EXPECT_EQ(
      error_of(with_joints(R"({"a1": 0.1})"), context),
      "obs.json: frames[0].joints: missing active joint 'a2' (every active joint needs a value)");
  EXPECT_EQ(error_of(with_joints(R"({"a1": 0.1, "a2": 0, "a3": 0})"), context),
            "obs.json: frames[0].joints.a3: unknown joint in arm.urdf");
  EXPECT_EQ(error_of(with_joints(R"({"a1": 0.1, "a2": 0, "finger": 0.01})"), context),
            "obs.json: frames[0].joints.finger: not an active joint of the robot");
  EXPECT_EQ(error_of(with_joints(R"({"a1": 0.1, "a2": "x"})"), context),
            "obs.json: frames[0].joints.a2: expected a number, got \"x\"");
  EXPECT_EQ(error_of(with_joints("[0, 0]"), context),
            "obs.json: frames[0].joints: expected an object of joint values, got [0,0]");
}

// A frame with a joint at 1e6 rad once made calibrate walk the model there for hours (issue 32).
TEST(Observations, JointsOutsideTheirLimitsBeyondTheMarginAreRefusedNamingJointAndLimits) {
  const RobotModel robot = two_joint_robot();  // both joints in [-2, 2]
  const ObservationContext context{.node_count = 8, .robot = &robot};
  auto with_a2 = [](double a2) {
    return R"({"frames": [{"points": [[0, 0, 0]], "joints": {"a1": 0, "a2": )" +
           nlohmann::json(a2).dump() + "}}]}";
  };
  EXPECT_EQ(error_of(with_a2(1e6), context),
            "obs.json: frames[0].joints.a2: expected a value within the joint's limits [-2, 2] "
            "give or take 0.01, got 1000000.0");
  EXPECT_NE(error_of(with_a2(2 + 1.5 * observation_joint_margin), context), "");
  EXPECT_NE(error_of(with_a2(-2 - 1.5 * observation_joint_margin), context), "");
  // Within the margin: a measured joint may read a little past its limit.
  EXPECT_EQ(parse(with_a2(2 + 0.5 * observation_joint_margin), context).frames[0].joints[1],
            2 + 0.5 * observation_joint_margin);
  EXPECT_EQ(parse(with_a2(-2), context).frames[0].joints[1], -2);
}

TEST(Observations, UnreadablePointsFilesNameTheFrameAndTheFile) {
  TempDir dir;
  const ObservationContext context{.node_count = 8};
  auto load_with = [&](const std::string& points_file) {
    const auto file =
        dir.write("obs.json", R"({"frames": [{"points_file": ")" + points_file + R"("}]})");
    return input_error_of([&] { load_observations(file, context); });
  };
  const std::string obs = (dir.path() / "obs.json").string();
  const std::string missing = load_with("none.xyz");
  EXPECT_EQ(missing.rfind(obs + ": frames[0].points_file: cannot read the point cloud: " +
                              (dir.path() / "none.xyz").string() + ": cannot open file",
                          0),
            0u)
      << missing;
  dir.write("bad.xyz", "0 0 0\n1 x 0\n");
  EXPECT_EQ(load_with("bad.xyz"), obs + ": frames[0].points_file: cannot read the point cloud: " +
                                      (dir.path() / "bad.xyz").string() +
                                      ":2: point 1: expected a number for y, got 'x'");
  dir.write("far.xyz", "0 0 0\n2000 0 0\n");
  EXPECT_EQ(load_with("far.xyz"), obs + ": frames[0].points_file: in " +
                                      (dir.path() / "far.xyz").string() +
                                      ": point 1 is 2000 m from the origin, more than 1000 m");
  dir.write("empty.xyz", "# nothing\n");
  EXPECT_EQ(load_with("empty.xyz"),
            obs + ": frames[0]: nothing observed; expected at least one marker or one point");
}

TEST(Observations, OneFrameFromAMessageNamesItsFields) {
  const ObservationContext context{.node_count = 3};
  const JsonInput message(parse_json_text(R"({"markers": [{"node": 2, "position": [0, 0, 1]}]})",
                                          "message"),
                          "message");
  const ObservationFrame frame = read_observation_frame(message, context);
  ASSERT_EQ(frame.markers.size(), 1u);
  EXPECT_EQ(frame.markers[0].position, Vec3(0, 0, 1));
  const JsonInput bad(parse_json_text(R"({"markers": [{"node": 3, "position": [0, 0, 1]}]})",
                                      "message"),
                      "message");
  EXPECT_EQ(input_error_of([&] { read_observation_frame(bad, context); }),
            "message: markers[0].node: expected a whole number from 0 to 2, got 3");
}

TEST(Observations, ListLengthsAreBoundedBeforeReading) {
  const ObservationContext context{.node_count = 3};
  nlohmann::json frames = nlohmann::json::array();
  const nlohmann::json frame = {{"points", {{0, 0, 0}}}};
  for (std::size_t k = 0; k <= max_observation_frames; ++k) frames.push_back(frame);
  const JsonInput many(nlohmann::json{{"frames", frames}}, "obs.json");
  EXPECT_EQ(input_error_of([&] { read_observations(many, context); }),
            "obs.json: frames: 10001 frames, more than the limit of 10000");
  nlohmann::json markers = nlohmann::json::array();
  for (std::size_t k = 0; k <= max_markers_per_frame; ++k) markers.push_back(nullptr);
  const JsonInput crowded(nlohmann::json{{"markers", markers}}, "message");
  EXPECT_EQ(input_error_of([&] { read_observation_frame(crowded, context); }),
            "message: markers: 100001 markers, more than the limit of 100000");
}

}  // namespace
}  // namespace shapectl
