// Checking a session log (`shapectl replay`): every field read with its type and its size
// checked against the log's own joint count; a malformed field is an InputError naming the line.
#include <shapectl/link/command_log.hpp>

#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

// A link with two joints on one channel, then two commands.
nlohmann::json link_event() {
  return nlohmann::json::parse(
      R"({"t":0,"event":"link","kind":"sim","joint_names":["a","b"],
          "channels":[{"name":"robot","joints":[0,1]}],"period":0.004,
          "lower":[-1,-1],"upper":[1,1],"velocity":[0.5,null],"acceleration":[1,1]})");
}

nlohmann::json command_event(double t, int seq, double q) {
  return {{"t", t},     {"event", "command"}, {"channel", "robot"},
          {"seq", seq}, {"joints", {q, 0.0}}, {"measured", {0.0, 0.0}}};
}

std::vector<nlohmann::json> good_log() {
  return {{{"t", 0}, {"event", "session"}, {"scene", "s.json"}, {"joint_names", {"a", "b"}}},
          link_event(),
          command_event(0.004, 1, 0),
          command_event(0.008, 2, 0.001),
          {{"t", 0.01}, {"event", "optimizer"}, {"joints", {0.1, 0.2}}, {"safe", true}}};
}

// Writes the log and checks it: the check, or the InputError's message.
std::string check_error(const std::vector<nlohmann::json>& lines,
                        CommandLogCheck* check = nullptr) {
  const test::TempDir dir;
  std::string text;
  for (const auto& l : lines) text += l.dump() + "\n";
  const auto file = dir.write("log.jsonl", text);
  try {
    const CommandLogCheck c = check_command_log(read_session_log(file), "log.jsonl");
    if (check) *check = c;
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CommandLogCheck, AWellFormedLogIsCheckedWithItsOptimizerResultsAndScene) {
  CommandLogCheck check;
  ASSERT_EQ(check_error(good_log(), &check), "no error");
  EXPECT_EQ(check.links, 1);
  EXPECT_EQ(check.commands, 2);
  EXPECT_TRUE(check.ok());
  EXPECT_EQ(check.scene, "s.json");
  ASSERT_EQ(check.optimizer_results.size(), 1u);
  EXPECT_EQ(check.optimizer_results[0].line, 5);
  EXPECT_EQ(check.optimizer_results[0].joints, Eigen::Vector2d(0.1, 0.2));
  EXPECT_TRUE(check.optimizer_results[0].safe);
}

// The reproducers of issue 32 (item 3): an empty or short limit array used to crash replay or
// read a limit from past the array.
TEST(CommandLogCheck, AnEmptyOrShortLimitArrayIsAnErrorNamingLineAndField) {
  for (const char* field : {"lower", "upper", "velocity", "acceleration"}) {
    for (const nlohmann::json& value : {nlohmann::json::array(), nlohmann::json{0.5}}) {
      auto log = good_log();
      log[1][field] = value;
      const std::string message = check_error(log);
      EXPECT_NE(message.find(std::string("log.jsonl:2: ") + field +
                             ": expected an array of 2 numbers or nulls, got " + value.dump()),
                std::string::npos)
          << message;
    }
  }
}

TEST(CommandLogCheck, WrongFieldTypesAreErrorsNamingLineFieldAndExpectation) {
  struct Case {
    int line;
    std::string field;
    nlohmann::json value;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {2, "period", "fast", "period: expected a number, got \"fast\""},
      {2, "period", 0, "period: expected a positive number, got 0"},
      {2, "joint_names", {"a", 3}, "joint_names[1]: expected a string, got 3"},
      {2, "joint_names", nlohmann::json::array(), "joint_names: expected 1 to 1000 joint names"},
      {2, "velocity", {0.5, -1}, "velocity[1]: expected a positive number or null, got -1"},
      {2, "upper", {-2, 1}, "upper[0]: expected a number >= lower (-1.000000), got -2"},
      {2,
       "channels",
       {{{"name", "robot"}, {"joints", {0, 2}}}},
       "channels[0].joints[1]: expected a whole number from 0 to 1, got 2"},
      {2, "channels", {{{"name", 7}, {"joints", {0}}}}, "channels[0].name: expected a string"},
      {1, "joint_names", "ab", "joint_names: expected an array, got \"ab\""},
      {1, "scene", 5, "scene: expected a string, got 5"},
      {3, "joints", {0.1}, "joints: expected an array of 2 numbers or nulls, got [0.1]"},
      {3, "joints", "x", "joints: expected an array of 2 numbers or nulls, got \"x\""},
      {3, "measured", {0, "y"}, "measured[1]: expected a number, got \"y\""},
      {3, "seq", -1, "seq: expected a whole number from 0"},
      {3, "hold", 1, "hold: expected true or false, got 1"},
      {3, "channel", 1, "channel: expected a string, got 1"},
      {5, "joints", {0.1, nullptr}, "joints[1]: expected a number, got null"},
      {5, "joints", {0.1, 0.2, 0.3}, "joints: expected an array of 2 numbers, got [0.1,0.2,0.3]"},
      {5, "safe", "yes", "safe: expected true or false, got \"yes\""},
  };
  for (const auto& c : cases) {
    auto log = good_log();
    log[static_cast<std::size_t>(c.line - 1)][c.field] = c.value;
    const std::string message = check_error(log);
    EXPECT_NE(message.find("log.jsonl:" + std::to_string(c.line) + ": " + c.expected),
              std::string::npos)
        << c.field << ": " << message;
  }
}

TEST(CommandLogCheck, ACommandOrConnectWithoutChannelIsAnErrorNamingTheLine) {
  auto log = good_log();
  log[2].erase("channel");
  EXPECT_NE(check_error(log).find("log.jsonl:3: channel: missing key"), std::string::npos)
      << check_error(log);
  log = good_log();
  log.insert(log.begin() + 2, nlohmann::json{{"t", 0.002}, {"event", "connect"}});
  EXPECT_NE(check_error(log).find("log.jsonl:3: channel: missing key"), std::string::npos)
      << check_error(log);
}

TEST(CommandLogCheck, AnOptimizerResultBeforeTheJointsAreNamedIsAnError) {
  const std::vector<nlohmann::json> log = {
      {{"t", 0}, {"event", "optimizer"}, {"joints", {0.1, 0.2}}}};
  EXPECT_NE(check_error(log).find("log.jsonl:1: joints: expected a \"session\" or \"link\" event"),
            std::string::npos)
      << check_error(log);
}

// serve's scene switch may change the robot: the optimizer results after it have its joints.
TEST(CommandLogCheck, ASceneSwitchNamesTheJointsOfTheOptimizerResultsAfterIt) {
  auto log = good_log();
  log.push_back(
      {{"t", 0.02}, {"event", "scene"}, {"scene", "b.json"}, {"joint_names", {"x", "y", "z"}}});
  log.push_back({{"t", 0.03}, {"event", "optimizer"}, {"joints", {0.1, 0.2, 0.3}}});
  CommandLogCheck check;
  ASSERT_EQ(check_error(log, &check), "no error");
  EXPECT_EQ(check.optimizer_results.back().joints.size(), 3);
  EXPECT_EQ(check.scene, "s.json") << "the session's scene";
  log.push_back({{"t", 0.04}, {"event", "optimizer"}, {"joints", {0.1, 0.2}}});
  EXPECT_NE(check_error(log).find("log.jsonl:8: joints: expected an array of 3 numbers, got"),
            std::string::npos)
      << check_error(log);
}

// A null joint (a NaN the link would have refused) is a limit violation, not a malformed log.
TEST(CommandLogCheck, ANonFiniteCommandIsAViolation) {
  auto log = good_log();
  log[3]["joints"] = {nullptr, 0.0};
  CommandLogCheck check;
  ASSERT_EQ(check_error(log, &check), "no error");
  ASSERT_EQ(check.violations.size(), 1u);
  EXPECT_NE(check.violations[0].find("log.jsonl:4: robot: command is not 2 finite values"),
            std::string::npos)
      << check.violations[0];
}

}  // namespace
}  // namespace shapectl
