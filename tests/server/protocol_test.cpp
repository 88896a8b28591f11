#include <shapectl/server/protocol.hpp>

#include <cstring>
#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>

namespace shapectl::server {
namespace {

ProtocolContext context() {
  ProtocolContext c;
  c.node_count = 10;
  c.joint_names = {"j1", "j2"};
  c.lower_limits = Eigen::Vector2d(-1, -2);
  c.upper_limits = Eigen::Vector2d(1, 2);
  c.scene_names = {"a.json", "b.json"};
  return c;
}

std::string error_of(const std::string& text) {
  try {
    parse_command(text, context());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Protocol, DegenerateCentrelineIsRefusedWithItsLength) {
  EXPECT_NE(
      error_of(
          R"({"type":"set_centerline","points":[[0.4,0,0.3],[0.4,1e-13,0.3],[0.4,2e-13,0.3]]})")
          .find("points: expected a centre-line at least 1 mm long (its arc length is 2e-13 m)"),
      std::string::npos);
  EXPECT_EQ(error_of(R"({"type":"set_centerline","points":[[0.4,0,0.3],[0.4,0.001,0.3]]})"), "");
}

TEST(Protocol, ParsesSetTargetWithItsId) {
  const Command c =
      parse_command(R"({"type":"set_target","id":7,"node":3,"position":[0.1,0.2,0.3]})", context());
  EXPECT_EQ(c.type, Command::Type::SetTarget);
  EXPECT_EQ(c.id, 7);
  EXPECT_EQ(c.node, 3);
  EXPECT_TRUE(c.position.isApprox(Vec3(0.1, 0.2, 0.3)));
}

TEST(Protocol, ParsesSetTargetsCenterlineJointsAndScenes) {
  const Command t = parse_command(
      R"({"type":"set_targets","targets":[{"node":1,"position":[0,0,0]},{"node":9,"position":[1,2,3]}]})",
      context());
  ASSERT_EQ(t.targets.size(), 2);
  EXPECT_EQ(t.targets.nodes[1], 9);
  const Command l =
      parse_command(R"({"type":"set_centerline","points":[[0,0,0],[0.1,0,0],[0.2,0.1,0]]})",
                    context());
  EXPECT_EQ(l.points.size(), 3u);
  const Command j = parse_command(R"({"type":"set_joint","joint":"j2","value":-1.5})", context());
  EXPECT_EQ(j.joint, 1);
  EXPECT_DOUBLE_EQ(j.value, -1.5);
  const Command js = parse_command(R"({"type":"set_joints","joints":[0.5,1.5]})", context());
  EXPECT_DOUBLE_EQ(js.joints[1], 1.5);
  EXPECT_EQ(parse_command(R"({"type":"load_scene","scene":"b.json"})", context()).scene, "b.json");
  EXPECT_TRUE(parse_command(R"({"type":"set_paused","paused":true})", context()).paused);
}

TEST(Protocol, ErrorsSayWhereWhatWasExpectedAndWhatWasFound) {
  EXPECT_EQ(error_of(R"({"type":"set_target","node":10,"position":[0,0,0]})"),
            "message: node: expected a whole number from 0 to 9, got 10");
  EXPECT_EQ(error_of(R"({"type":"set_targets","targets":[{"node":1,"position":[0,"x",0]}]})"),
            "message: targets[0].position[1]: expected a number, got \"x\"");
  EXPECT_EQ(error_of(R"({"type":"set_paused","paused":1})"),
            "message: paused: expected true or false, got 1");
  EXPECT_EQ(error_of(R"({"type":"reset","extra":1})"),
            "message: extra: unknown key; known: type, id");
  EXPECT_EQ(error_of("{\"type\":"), "message: not valid JSON");
  // A key given twice is an error, never silently the last one (the paused state would flip).
  const std::string twice = error_of(R"({"type":"set_paused","paused":true,"paused":false})");
  EXPECT_NE(twice.find("paused"), std::string::npos) << twice;
  EXPECT_NE(twice.find("duplicate key"), std::string::npos) << twice;
  EXPECT_NE(
      error_of(R"({"type":"launch"})").find("message: type: expected one of ping, set_target"),
      std::string::npos);
}

TEST(Protocol, RejectsOutOfRangeAndNonFiniteNumbers) {
  EXPECT_NE(error_of(R"({"type":"set_target","node":1,"position":[1e400,0,0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_target","node":1,"position":[11,0,0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_target","node":-1,"position":[0,0,0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_target","node":1.5,"position":[0,0,0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_target","node":1,"position":[0,0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_joint","joint":0,"value":1.01})"), "");
  EXPECT_NE(error_of(R"({"type":"set_joint","joint":2,"value":0})"), "");
  EXPECT_NE(error_of(R"({"type":"set_joints","joints":[0]})"), "");
  EXPECT_NE(error_of(R"({"type":"set_centerline","points":[[0,0,0]]})"), "");
  EXPECT_NE(
      error_of(
          R"({"type":"set_targets","targets":[{"node":1,"position":[0,0,0]},{"node":1,"position":[0,0,0]}]})"),
      "");
  EXPECT_NE(error_of(R"({"type":"load_scene","scene":"../../etc/passwd"})"), "");
  EXPECT_NE(error_of(R"({"type":"ping","id":{"a":1}})"), "");
  EXPECT_NE(error_of(R"([1,2,3])"), "");
}

TEST(Protocol, RefusesDeepNestingAndOversizedMessages) {
  EXPECT_NE(error_of(std::string(100000, '[') + std::string(100000, ']')).find("nested"),
            std::string::npos);
  const std::string big = R"({"type":"ping","pad":")" + std::string(max_message_bytes, 'x') + "\"}";
  EXPECT_NE(error_of(big).find("bytes"), std::string::npos);
}

TEST(Protocol, ErrorRepliesCarryTheIdWhenItCanBeRead) {
  EXPECT_EQ(message_id(R"({"type":"launch","id":"abc"})"), "abc");
  EXPECT_TRUE(message_id("not json").is_null());
  EXPECT_TRUE(message_id(R"({"id":[1]})").is_null());
  const auto reply = nlohmann::json::parse(error_reply(5, "bad \xff bytes"));
  EXPECT_EQ(reply["type"], "error");
  EXPECT_EQ(reply["id"], 5);
}

TEST(Protocol, PositionsFrameHasHeaderAndFloats) {
  ControllerSnapshot s;
  s.sequence = 42;
  s.positions = Eigen::VectorXd::LinSpaced(6, 0.0, 0.5);
  const std::string frame = positions_frame(s);
  ASSERT_EQ(frame.size(), 16u + 24u);
  EXPECT_EQ(frame.substr(0, 4), "POS1");
  std::uint32_t n = 0;
  double sequence = 0;
  float last = 0;
  std::memcpy(&n, frame.data() + 4, 4);
  std::memcpy(&sequence, frame.data() + 8, 8);
  std::memcpy(&last, frame.data() + 16 + 20, 4);
  EXPECT_EQ(n, 2u);
  EXPECT_EQ(sequence, 42.0);
  EXPECT_FLOAT_EQ(last, 0.5f);
}

}  // namespace
}  // namespace shapectl::server
