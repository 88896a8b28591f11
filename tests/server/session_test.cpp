#include <shapectl/server/session.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include <shapectl/io/session_log.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "support/controller_wait.hpp"
#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

nlohmann::json reply_json(const Session::Reply& r) { return nlohmann::json::parse(r.text); }

// Waits (generously) until the controller has published a snapshot that satisfies `done`.
template <class Done>
std::shared_ptr<const ControllerSnapshot> wait_until(Session& session, Done done) {
  return test::wait_until(session.controller(), done, 60);
}

class SessionTest : public ::testing::Test {
 protected:
  Session session{test::source_path("scenes/yumi_bar.json"),
                  find_bundled_scenes(test::source_path("scenes"))};
};

TEST_F(SessionTest, SceneMessageDescribesRobotObjectAndScenes) {
  const auto m = nlohmann::json::parse(session.scene_message());
  EXPECT_EQ(m["type"], "scene");
  EXPECT_EQ(m["scene"], "yumi_bar.json");
  EXPECT_GT(m["node_count"].get<int>(), 0);
  EXPECT_EQ(m["triangles"].size() % 3, 0u);
  EXPECT_GT(m["triangles"].size(), 0u);
  EXPECT_EQ(m["robot"]["joint_names"].size(), 14u);
  EXPECT_GT(m["robot"]["links"].size(), 14u);
  EXPECT_EQ(m["grips"].size(), 2u);
  EXPECT_FALSE(m["bar"].is_null());
  const auto& scenes = m["scenes"];
  EXPECT_NE(std::find(scenes.begin(), scenes.end(), "yumi_bar.json"), scenes.end());
  EXPECT_EQ(std::find(scenes.begin(), scenes.end(), "foam_bar_clamped.json"), scenes.end())
      << "scenes without a robot are not offered";
}

TEST_F(SessionTest, SceneMessageNamesTheArmEachJointMoves) {
  const auto robot = nlohmann::json::parse(session.scene_message())["robot"];
  const auto& names = robot["joint_names"];
  const auto& arms = robot["joint_arms"];
  ASSERT_EQ(arms.size(), names.size());
  // The YuMi's joints end in _l (left arm) or _r (right arm); its end effectors are named so.
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string name = names[k];
    EXPECT_EQ(arms[k], name.ends_with("_l") ? "left" : "right") << name;
  }
}

TEST_F(SessionTest, SetTargetReachesTheControllerAndTheStateMessage) {
  const auto r =
      session.handle(R"({"type":"set_target","id":1,"node":5,"position":[0.4,0.0,0.3]})");
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(reply_json(r)["type"], "ok");
  EXPECT_EQ(reply_json(r)["id"], 1);
  // Marked as editing right after the edit (the window is 0.3 s; this takes microseconds).
  EXPECT_TRUE(nlohmann::json::parse(session.state_message(1))["editing"].get<bool>());
  const auto s =
      wait_until(session, [](const ControllerSnapshot& s) { return s.targets.size() == 1; });
  ASSERT_EQ(s->targets.size(), 1);
  EXPECT_EQ(s->targets.nodes[0], 5);
  session.tick();
  const auto state = nlohmann::json::parse(session.state_message(1));
  EXPECT_EQ(state["targets"].size(), 1u);
  EXPECT_EQ(state["links"].size(), session.controller().robot().links().size());
  EXPECT_EQ(state["links"][0].size(), 16u);
}

TEST_F(SessionTest, ObserveFeedsTheClosedLoopAndBadObservationsChangeNothing) {
  const auto first = session.controller().snapshot();
  nlohmann::json joints = nlohmann::json::object();
  for (std::size_t j = 0; j < first->joint_names.size(); ++j)
    joints[first->joint_names[j]] = first->joints[j];
  const Vec3 seen =
      first->positions.segment<3>(15) + Vec3(0.002, 0, 0);  // node 5, 2 mm off the model
  const nlohmann::json frame = {{"joints", joints},
                                {"markers",
                                 {{{"node", 5}, {"position", {seen.x(), seen.y(), seen.z()}}}}}};
  auto observe = [&](const nlohmann::json& f) {
    return session.handle(nlohmann::json{{"type", "observe"}, {"frame", f}}.dump());
  };
  std::vector<nlohmann::json> bad(5, frame);
  bad[0]["markers"][0]["node"] = 100000;
  bad[1]["joints"].erase(first->joint_names[3]);
  bad[2]["points_file"] = "/etc/passwd";
  bad[3].erase("markers");  // nothing observed
  bad[4]["markers"][0]["position"][1] = "nan";
  for (const auto& b : bad) {
    const auto r = observe(b);
    EXPECT_FALSE(r.ok) << b.dump();
    EXPECT_EQ(reply_json(r)["type"], "error");
  }
  EXPECT_TRUE(session.handle(R"({"type":"set_feedback","on":true})").ok);
  const auto r = observe(frame);
  ASSERT_TRUE(r.ok) << r.text;
  const auto s =
      wait_until(session, [](const ControllerSnapshot& s) { return s.observations > 0; });
  EXPECT_EQ(s->observations, 1u);  // the bad ones never reached the controller
  session.tick();
  const auto state = nlohmann::json::parse(session.state_message(1));
  EXPECT_TRUE(state["feedback"].get<bool>());
  EXPECT_NEAR(state["model_error"].get<double>(), 0.002, 1e-6);
  ASSERT_EQ(state["observed_markers"].size(), 1u);
  EXPECT_EQ(state["observed_markers"][0][0], 5);
}

// A lying frame (a marker 1 m off the model) is refused by the plausibility gate: counted in
// the state, said why, logged, and no correction applied (docs/calibration.md, Safety).
TEST(SessionGate, AFrameOutsideTheGateIsCountedInTheStateAndLogged) {
  test::TempDir dir;
  const auto file = dir.path() / "session.jsonl";
  nlohmann::json state;
  {
    SessionLog log(file);
    Session session(test::source_path("scenes/yumi_bar.json"), {});
    session.set_log(&log);
    const auto first = session.controller().snapshot();
    nlohmann::json joints = nlohmann::json::object();
    for (std::size_t j = 0; j < first->joint_names.size(); ++j)
      joints[first->joint_names[j]] = first->joints[j];
    const Vec3 lie = first->positions.segment<3>(15) + Vec3(0, 0, 1);
    const nlohmann::json frame = {{"joints", joints},
                                  {"markers",
                                   {{{"node", 5}, {"position", {lie.x(), lie.y(), lie.z()}}}}}};
    ASSERT_TRUE(session.handle(R"({"type":"set_feedback","on":true})").ok);
    ASSERT_TRUE(session.handle(nlohmann::json{{"type", "observe"}, {"frame", frame}}.dump()).ok);
    const auto s =
        wait_until(session, [](const ControllerSnapshot& s) { return s.gate.frames_checked > 0; });
    EXPECT_EQ(s->gate.frames_rejected, 1u);
    session.tick();
    state = nlohmann::json::parse(session.state_message(1));
  }
  EXPECT_EQ(state["observations"], 0);
  EXPECT_EQ(state["gate"]["markers_checked"], 1);
  EXPECT_EQ(state["gate"]["markers_rejected"], 1);
  EXPECT_EQ(state["gate"]["frames_rejected"], 1);
  EXPECT_EQ(state["authority"]["max_correction"], 0.03);
  EXPECT_EQ(state["authority"]["max_correction_rate"], 0.02);
  EXPECT_EQ(state["authority"]["largest"], 0);
  EXPECT_NE(state["observation_problem"].get<std::string>().find(
                "observation gated: 1 of 1 markers outside the gate (largest innovation 1000.0 mm"),
            std::string::npos)
      << state["observation_problem"];
  const auto events = read_session_log(file);
  const auto gate = std::find_if(events.begin(), events.end(),
                                 [](const LoggedEvent& e) { return e.event == "gate"; });
  ASSERT_NE(gate, events.end());
  EXPECT_EQ(gate->fields["gate"]["frames_rejected"], 1);
  EXPECT_EQ(gate->fields["authority"]["max_correction"], 0.03);
  EXPECT_NE(gate->fields["problem"].get<std::string>().find("outside the gate"), std::string::npos);
}

// Issue 32: such a frame once went into the calibration window, whose fit then walked the model
// towards 1e6 rad for hours and left the session "calibrating".
TEST_F(SessionTest, AnObservationWithAJointAtAMillionRadiansIsRejectedCountedAndNamed) {
  const auto first = session.controller().snapshot();
  nlohmann::json joints = nlohmann::json::object();
  for (std::size_t j = 0; j < first->joint_names.size(); ++j)
    joints[first->joint_names[j]] = first->joints[j];
  joints[first->joint_names[3]] = 1e6;
  const nlohmann::json frame = {{"joints", joints},
                                {"markers", {{{"node", 5}, {"position", {0.4, 0.0, 0.3}}}}}};
  const auto r = session.handle(nlohmann::json{{"type", "observe"}, {"frame", frame}}.dump());
  EXPECT_FALSE(r.ok);
  const std::string field =
      "frame.joints." + first->joint_names[3] + ": expected a value within the joint's limits";
  EXPECT_NE(reply_json(r)["message"].get<std::string>().find(field), std::string::npos) << r.text;
  EXPECT_NE(r.log.find(field), std::string::npos) << r.log;  // the server's log line
  EXPECT_FALSE(session.handle(R"({"type":"remove_target","node":-1})").ok);  // not an observation
  session.tick();
  const auto state = nlohmann::json::parse(session.state_message(1));
  EXPECT_EQ(state["observations_rejected"], 1);
  EXPECT_NE(state["observation_rejection"].get<std::string>().find(field), std::string::npos);
  EXPECT_EQ(state["calibration"]["frames"], 0);
  EXPECT_EQ(state["observations"], 0);
}

TEST_F(SessionTest, ObservedFramesFeedTheCalibrationWhichTheClientsCanRunAndFollow) {
  const auto first = session.controller().snapshot();
  nlohmann::json joints = nlohmann::json::object();
  for (std::size_t j = 0; j < first->joint_names.size(); ++j)
    joints[first->joint_names[j]] = first->joints[j];
  EXPECT_TRUE(session.handle(R"({"type":"set_auto_calibration","on":false})").ok);
  auto r = session.handle(R"({"type":"calibrate","id":4})");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("no observed frames yet"), std::string::npos) << r.text;
  EXPECT_EQ(reply_json(r)["id"], 4);

  // A depth camera's frame: points only, on the model's own surface 1 mm lower.
  nlohmann::json points = nlohmann::json::array();
  for (int node = 0; node < 40; ++node) {
    const Vec3 p = first->positions.segment<3>(3 * node) - Vec3(0, 0, 0.001);
    points.push_back({p.x(), p.y(), p.z()});
  }
  const nlohmann::json frame = {{"joints", joints}, {"points", points}};
  r = session.handle(nlohmann::json{{"type", "observe"}, {"frame", frame}}.dump());
  ASSERT_TRUE(r.ok) << r.text;
  session.tick();
  auto state = nlohmann::json::parse(session.state_message(1));
  EXPECT_EQ(state["observed_points"].size(), 40u);
  EXPECT_FALSE(state["calibration"]["automatic"].get<bool>());
  EXPECT_EQ(state["calibration"]["frames"], 1);
  EXPECT_TRUE(state["calibration"]["result"].is_null());
  EXPECT_EQ(state["model"]["youngs_modulus"].get<double>(),
            youngs_modulus_of(session.controller().scene().material));

  ASSERT_TRUE(session.handle(R"({"type":"calibrate"})").ok);
  for (int k = 0; k < 6000 && state["calibration"]["runs"] == 0; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    session.tick();
    state = nlohmann::json::parse(session.state_message(1));
  }
  const nlohmann::json& result = state["calibration"]["result"];
  ASSERT_FALSE(result.is_null()) << state["calibration"].dump();
  ASSERT_FALSE(result["parameters"].empty());
  EXPECT_EQ(result["parameters"][0]["name"], "youngs_modulus");
  EXPECT_EQ(result["parameters"][0]["unit"], "Pa");
  EXPECT_GT(result["rms_before"].get<double>(), 0);
  EXPECT_TRUE(result["applied"].is_boolean());
  EXPECT_FALSE(session.handle(R"({"type":"calibrate","extra":1})").ok);
  EXPECT_FALSE(session.handle(R"({"type":"set_auto_calibration","on":"yes"})").ok);
}

TEST_F(SessionTest, SecondSetTargetMovesTheFirstAndRemoveTargetDeletesIt) {
  // Paused, requests apply without waiting for optimizer iterations.
  EXPECT_TRUE(session.handle(R"({"type":"set_paused","paused":true})").ok);
  EXPECT_TRUE(session.handle(R"({"type":"set_target","node":5,"position":[0.4,0.0,0.3]})").ok);
  EXPECT_TRUE(session.handle(R"({"type":"set_target","node":6,"position":[0.4,0.0,0.3]})").ok);
  EXPECT_TRUE(session.handle(R"({"type":"set_target","node":5,"position":[0.41,0.0,0.3]})").ok);
  auto s = wait_until(session, [](const ControllerSnapshot& s) {
    return s.targets.size() == 2 && s.targets.positions[0].x() > 0.405;
  });
  ASSERT_EQ(s->targets.size(), 2);
  EXPECT_DOUBLE_EQ(s->targets.positions[0].x(), 0.41);
  EXPECT_TRUE(session.handle(R"({"type":"remove_target","node":5})").ok);
  s = wait_until(session, [](const ControllerSnapshot& s) { return s.targets.size() == 1; });
  ASSERT_EQ(s->targets.size(), 1);
  EXPECT_EQ(s->targets.nodes[0], 6);
  EXPECT_FALSE(session.handle(R"({"type":"remove_target","node":5})").ok);
}

TEST_F(SessionTest, BadMessagesGetAnErrorReplyAndChangeNothing) {
  EXPECT_TRUE(session.handle(R"({"type":"set_paused","paused":true})").ok);
  EXPECT_TRUE(session.handle(R"({"type":"set_target","node":5,"position":[0.4,0.0,0.3]})").ok);
  for (const char* bad :
       {"", "nonsense", R"({"type":"set_target","id":3,"node":100000,"position":[0,0,0]})",
        R"({"type":"set_targets","targets":[]}x)",
        R"({"type":"load_scene","scene":"/etc/passwd"})"}) {
    const auto r = session.handle(bad);
    EXPECT_FALSE(r.ok) << bad;
    EXPECT_EQ(reply_json(r)["type"], "error");
    EXPECT_FALSE(r.log.empty());
  }
  EXPECT_EQ(reply_json(session.handle(R"({"type":"nope","id":3})"))["id"], 3);
  const auto s =
      wait_until(session, [](const ControllerSnapshot& s) { return s.targets.size() == 1; });
  EXPECT_EQ(s->targets.size(), 1);
  EXPECT_EQ(s->targets.nodes[0], 5);
}

// Issue 10, finding 5: a degenerate centre-line and absurd targets are refused; the session
// keeps its target and no state message carries a null coordinate.
TEST_F(SessionTest, DegenerateCentrelineAndAbsurdTargetsGetAnErrorAndChangeNothing) {
  EXPECT_TRUE(session.handle(R"({"type":"set_target","node":5,"position":[0.4,0.0,0.3]})").ok);
  wait_until(session, [](const ControllerSnapshot& s) { return s.targets.size() == 1; });
  for (const char* bad :
       {R"({"type":"set_centerline","points":[[0.4,0,0.3],[0.4,1e-13,0.3],[0.4,2e-13,0.3]]})",
        R"({"type":"set_centerline","points":[[0.4,0,0.3],[0.4,0,0.3]]})",
        R"({"type":"set_target","node":5,"position":[1e155,0,0]})",
        R"({"type":"set_target","node":6,"position":[0,-1e300,0]})",
        R"({"type":"set_targets","targets":[{"node":5,"position":[1e155,1e155,0]}]})",
        R"({"type":"set_centerline","points":[[0.4,0,0.3],[1e155,0,0.3]]})"}) {
    const auto r = session.handle(bad);
    EXPECT_FALSE(r.ok) << bad;
    EXPECT_EQ(reply_json(r)["type"], "error") << bad;
  }
  for (int k = 0; k < 5; ++k) {
    session.tick();
    const std::string state = session.state_message(1);
    const auto m = nlohmann::json::parse(state);
    ASSERT_EQ(m["targets"].size(), 1u);
    EXPECT_EQ(m["targets"][0]["node"], 5);
    EXPECT_TRUE(m["centerline"].empty());
    for (const char* field : {"targets", "centerline", "joints", "links", "error"})
      EXPECT_EQ(m[field].dump().find("null"), std::string::npos)
          << field << ": " << m[field].dump();
  }
}

TEST_F(SessionTest, JoggingNeedsPauseAndArmingNeedsALink) {
  // One jog step (at most 0.05 rad) from where joint 0 is, and a jump of 1 rad.
  const double goal =
      nlohmann::json::parse(session.state_message(1))["joints"][0].get<double>() + 0.04;
  const std::string jog = R"({"type":"set_joint","joint":0,"value":)" + std::to_string(goal) + "}";
  const std::string jump =
      R"({"type":"set_joint","joint":0,"value":)" + std::to_string(goal + 1) + "}";
  EXPECT_FALSE(session.handle(jog).ok);
  EXPECT_TRUE(session.handle(R"({"type":"set_paused","paused":true})").ok);
  EXPECT_TRUE(wait_until(session, [](const ControllerSnapshot& s) { return s.paused; })->paused);
  EXPECT_NE(reply_json(session.handle(jump))["message"].get<std::string>().find(
                "jog refused: yumi_joint_1_l: expected a step of at most 0.05 rad"),
            std::string::npos);
  EXPECT_TRUE(session.handle(jog).ok);
  const double sent = std::stod(std::to_string(goal));
  const auto s = wait_until(session, [&](const ControllerSnapshot& s) {
    return std::abs(s.joints[0] - sent) < 1e-9;
  });
  EXPECT_NEAR(s->joints[0], sent, 1e-9);
  EXPECT_NE(reply_json(session.handle(R"({"type":"arm"})"))["message"].get<std::string>().find(
                "no robot link"),
            std::string::npos);
}

TEST(SessionScenes, BundledScenesAreTheOnesWithARobot) {
  test::TempDir dir;
  dir.write("b.json", R"({"robot": {}})");
  dir.write("a.json", R"({"robot": {}, "object": {}})");
  dir.write("plain.json", R"({"object": {}})");
  dir.write("broken.json", "{");
  dir.write("notes.txt", R"({"robot": {}})");
  const auto scenes = find_bundled_scenes(dir.path());
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_EQ(scenes[0].name, "a.json");
  EXPECT_EQ(scenes[1].name, "b.json");
}

// yumi_bar.json in `dir` as `name` (bundled_scene_text makes its file names absolute);
// `drop_joint` (if not empty) held fixed at its reference value instead of active.
std::filesystem::path yumi_scene_copy(const test::TempDir& dir, const std::string& name,
                                      const std::string& drop_joint = "") {
  auto scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  auto& robot = scene["robot"];
  if (!drop_joint.empty()) {
    auto& active = robot["active_joints"];
    active.erase(std::find(active.begin(), active.end(), drop_joint));
    robot["fixed_joints"][drop_joint] = robot["reference_joints"][drop_joint];
    robot["reference_joints"].erase(drop_joint);
  }
  return dir.write(name, scene.dump());
}

TEST(SessionScenes, WithARobotLinkOnlyScenesWithItsJointsAreOffered) {
  test::TempDir dir;
  const auto first = yumi_scene_copy(dir, "a_yumi.json");
  yumi_scene_copy(dir, "b_same_yumi.json");
  yumi_scene_copy(dir, "c_one_joint_fixed.json", "yumi_joint_6_r");
  const Scene scene = load_scene(first);
  const auto link = make_robot_link(LinkConfig{}, *scene.robot->model, scene.robot->collisions);
  Session session(first, find_bundled_scenes(dir.path()), link.get());
  const auto scenes = nlohmann::json::parse(session.scene_message())["scenes"];
  EXPECT_EQ(scenes, nlohmann::json({"a_yumi.json", "b_same_yumi.json"}));
  // Without a link every scene with a robot is offered.
  Session free(first, find_bundled_scenes(dir.path()));
  EXPECT_EQ(nlohmann::json::parse(free.scene_message())["scenes"].size(), 3u);
}

TEST(SessionLog, EachNewSnapshotIsLoggedAsAnOptimizerEvent) {
  test::TempDir dir;
  const auto file = dir.path() / "session.jsonl";
  {
    SessionLog log(file);
    Session session(test::source_path("scenes/yumi_bar.json"), {});
    session.set_log(&log);
    ASSERT_TRUE(
        session.handle(R"({"type":"set_target","id":1,"node":5,"position":[0.4,0.0,0.3]})").ok);
    const auto s =
        wait_until(session, [](const ControllerSnapshot& s) { return !s.targets.empty(); });
    ASSERT_FALSE(s->targets.empty());
    session.tick();
    session.tick();  // nothing new, or a newer snapshot: never the same one twice
  }
  const auto events = read_session_log(file);
  ASSERT_FALSE(events.empty());
  std::vector<std::uint64_t> sequences;
  for (const auto& e : events) {
    ASSERT_EQ(e.event, "optimizer");
    EXPECT_EQ(e.fields["joints"].size(), 14u);
    sequences.push_back(e.fields["sequence"].get<std::uint64_t>());
  }
  EXPECT_TRUE(std::adjacent_find(sequences.begin(), sequences.end()) == sequences.end());
}

TEST(SessionLog, ASceneSwitchIsLogged) {
  test::TempDir dir;
  const auto file = dir.path() / "session.jsonl";
  {
    SessionLog log(file);
    Session session(test::source_path("scenes/yumi_bar.json"),
                    find_bundled_scenes(test::source_path("scenes")));
    session.set_log(&log);
    ASSERT_TRUE(session.handle(R"({"type":"load_scene","scene":"yumi_frame.json"})").ok);
    EXPECT_FALSE(session.handle(R"({"type":"load_scene","scene":"nowhere.json"})").ok);
  }
  const auto events = read_session_log(file);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].event, "scene");
  EXPECT_EQ(events[0].fields["scene"], test::source_path("scenes/yumi_frame.json").string());
  EXPECT_EQ(events[0].fields["joint_names"].size(), 14u);  // replay checks optimizer results
}

}  // namespace
}  // namespace shapectl::server
