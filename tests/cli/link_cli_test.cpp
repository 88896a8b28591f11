// `shapectl run`, `egm-sim` and `replay`: the headless chain end to end, exit codes, messages.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/server/session.hpp>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

// The YuMi bar scene with a coarse mesh (fast), paths made absolute.
std::filesystem::path small_yumi_scene(const TempDir& dir) {
  auto scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  scene["object"]["mesh"]["box"]["cells"] = {4, 1, 1};
  return dir.write("scene.json", scene.dump());
}

std::filesystem::path lift_targets(const TempDir& dir) {
  return dir.write("targets.json",
                   R"({"centerline": [[0.39047, -0.15, 0.28], [0.39047, 0.15, 0.28]]})");
}

// `run` with the simulated robot, armed, until settled, writing the session log `log`.
test::CliRun run_sim_with_log(const TempDir& dir, const std::filesystem::path& log,
                              const std::vector<std::string>& more = {}) {
  std::vector<std::string> args = {"run",       small_yumi_scene(dir).string(),
                                   "--targets", lift_targets(dir).string(),
                                   "--arm",     "--until-settled",
                                   "--timeout", "60",
                                   "--log",     log.string()};
  args.insert(args.end(), more.begin(), more.end());
  return run_cli(args);
}

// A CLI process running in the background; stdout goes to a file.
class Background {
 public:
  Background(const std::vector<std::string>& args, std::filesystem::path out)
      : out_(std::move(out)) {
    pid_ = test::start_process(test::cli_command(args), out_, "/dev/null");
  }
  // Asks it to stop (SIGTERM) and returns its exit code and output.
  std::pair<int, std::string> finish() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test::read_text(out_)};
  }
  ~Background() {
    if (pid_ > 0) kill(pid_, SIGKILL), waitpid(pid_, nullptr, 0);
  }

 private:
  pid_t pid_ = -1;
  std::filesystem::path out_;
};

int free_port_pair_base() {
  std::random_device rd;
  return 20000 + static_cast<int>(rd() % 20000) * 2;
}

TEST(RunCli, SimRobotSettlesAndTheLogReplaysWithinTheLimits) {
  TempDir dir;
  const auto log = dir.path() / "session.jsonl";
  const auto run = run_sim_with_log(dir, log);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(run.out);
  EXPECT_TRUE(result["settled"].get<bool>());
  EXPECT_EQ(result["status"], "reached");
  EXPECT_EQ(result["unreachable"], nlohmann::json::array());
  EXPECT_EQ(result["link"]["kind"], "sim");
  // The robot stands exactly at the optimizer's θ.
  EXPECT_EQ(result["link"]["measured"], result["joints"]);

  const auto replay = run_cli({"replay", log.string(), "--robot", "sim", "--arm", "--speed", "4"});
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  const auto summary = nlohmann::json::parse(replay.out);
  EXPECT_GT(summary["commands_checked"].get<int>(), 10);
  EXPECT_TRUE(summary["violations"].empty());
  EXPECT_LE(summary["velocity_ratio"].get<double>(), 1 + 1e-9);
  EXPECT_EQ(summary["counts"]["arm"], 1);

  // Issue 36: its stdout is a result --joints takes, fixed joints included.
  const auto result_file = dir.write("run.json", run.out);
  const auto statics_out = dir.path() / "statics.json";
  const auto statics = run_cli({"statics", small_yumi_scene(dir).string(), "--joints",
                                result_file.string(), "--out", statics_out.string()});
  ASSERT_EQ(statics.exit_code, 0) << statics.err;
  const auto again = nlohmann::json::parse(test::read_text(statics_out));
  ASSERT_EQ(result["joint_names"].size(), result["joints"].size());
  for (std::size_t k = 0; k < result["joints"].size(); ++k)
    EXPECT_EQ(again["joints"][result["joint_names"][k].get<std::string>()], result["joints"][k]);
  EXPECT_EQ(again["fixed_joints"], result["fixed_joints"]);
  EXPECT_EQ(result["fixed_joints"].size(), 2u);
}

TEST(RunCli, EgmRobotThroughEgmSimSettlesWithinTheLimits) {
  TempDir dir;
  const int port = free_port_pair_base();
  const auto scene = small_yumi_scene(dir);
  Background sim({"egm-sim", "--left-port", std::to_string(port), "--right-port",
                  std::to_string(port + 1), "--scene", scene.string(), "--duration", "120"},
                 dir.path() / "sim.json");
  const auto log = dir.path() / "egm.jsonl";
  const auto run = run_cli({"run", scene.string(), "--targets", lift_targets(dir).string(),
                            "--robot", "egm", "--egm-address", "127.0.0.1", "--egm-left-port",
                            std::to_string(port), "--egm-right-port", std::to_string(port + 1),
                            "--arm", "--until-settled", "--timeout", "60", "--log", log.string()});
  const auto [sim_exit, sim_out] = sim.finish();
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const auto result = nlohmann::json::parse(run.out);
  EXPECT_TRUE(result["settled"].get<bool>());
  EXPECT_EQ(result["link"]["kind"], "egm");
  EXPECT_EQ(result["link"]["rejected_datagrams"], 0);
  EXPECT_EQ(result["link"]["foreign_datagrams"], 0);  // egm-sim sends each arm from one socket
  EXPECT_EQ(result["link"]["stale_datagrams"], 0);
  EXPECT_GT(result["latency_us"]["samples"].get<int>(), 100);

  ASSERT_EQ(sim_exit, 0);
  const auto stats = nlohmann::json::parse(sim_out);
  for (const char* arm : {"left", "right"}) {
    EXPECT_GT(stats[arm]["commands"].get<int>(), 100) << arm;
    EXPECT_EQ(stats[arm]["outside_limits"], 0) << arm;
    EXPECT_LE(stats[arm]["max_speed"].get<double>(), 0.5 + 1e-6) << arm;  // --max-velocity default
    EXPECT_LE(stats[arm]["max_acceleration"].get<double>(), 1.0 + 1e-3) << arm;
  }
  const auto replay = run_cli({"replay", log.string()});
  ASSERT_EQ(replay.exit_code, 0) << replay.err << replay.out;
}

TEST(RunCli, EgmWithoutARobotCannotArm) {
  TempDir dir;
  const int port = free_port_pair_base();
  const auto run = run_cli(
      {"run", small_yumi_scene(dir).string(), "--targets", lift_targets(dir).string(), "--robot",
       "egm", "--egm-address", "127.0.0.1", "--egm-left-port", std::to_string(port),
       "--egm-right-port", std::to_string(port + 1), "--arm", "--until-settled"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("cannot arm the robot link: left: no feedback"), std::string::npos)
      << run.err;
}

TEST(RunCli, BadLinkSettingsAreBadInput) {
  TempDir dir;
  const auto scene = small_yumi_scene(dir).string();
  const auto targets = lift_targets(dir).string();
  auto run = run_cli({"run", scene, "--targets", targets, "--max-velocity", "-1"});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("link: max_velocity: expected a positive number, got -1"),
            std::string::npos)
      << run.err;

  run = run_cli({"run", scene, "--targets", (dir.path() / "none.json").string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("none.json"), std::string::npos) << run.err;

  run = run_cli(
      {"run", test::source_path("scenes/foam_bar_clamped.json").string(), "--targets", targets});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("run needs a scene with a robot"), std::string::npos) << run.err;
}

TEST(ReplayCli, AViolatedLimitIsReportedWithItsLine) {
  TempDir dir;
  const auto log = dir.write(
      "bad.jsonl",
      R"({"t":0,"event":"link","kind":"sim","joint_names":["a"],"channels":[{"name":"robot","joints":[0]}],"period":0.004,"lower":[-1],"upper":[1],"velocity":[0.5],"acceleration":[1]})"
      "\n"
      R"({"t":0.004,"event":"command","channel":"robot","seq":1,"joints":[0.0],"measured":[0.0]})"
      "\n"
      R"({"t":0.008,"event":"command","channel":"robot","seq":2,"joints":[0.1],"measured":[0.0]})"
      "\n");
  const auto run = run_cli({"replay", log.string()});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("bad.jsonl:3: robot joint 0: step"), std::string::npos) << run.err;
}

TEST(ReplayCli, AMalformedLogIsBadInputNamingTheLine) {
  TempDir dir;
  const auto log =
      dir.write("m.jsonl", "{\"t\":0,\"event\":\"a\"}\n[1,2]\n{\"t\":1,\"event\":\"b\"}\n");
  const auto run = run_cli({"replay", log.string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("m.jsonl:2:"), std::string::npos) << run.err;
}

// issue 32: replay of an empty log exited 0 having checked nothing.
TEST(ReplayCli, AnEmptyLogOrOneWithNothingToCheckIsBadInput) {
  TempDir dir;
  for (const char* text : {"", "\n\n", "{\"t\":0,\"event\":\"sess"}) {
    const auto run = run_cli({"replay", dir.write("e.jsonl", text).string()});
    EXPECT_EQ(run.exit_code, 1) << text;
    EXPECT_NE(run.err.find("e.jsonl: an empty log: expected JSON lines"), std::string::npos)
        << run.err;
  }
  const auto run =
      run_cli({"replay", dir.write("s.jsonl", R"({"t":0,"event":"session","scene":"a.json"})"
                                              "\n")
                             .string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("s.jsonl: nothing to check: expected \"command\" or \"optimizer\" "
                         "events, got 1 other events"),
            std::string::npos)
      << run.err;
}

// issue 32: an empty limit array segfaulted, a command without a channel was exit 3.
TEST(ReplayCli, MalformedFieldsAreBadInputNamingLineAndField) {
  TempDir dir;
  const std::string link =
      R"({"t":0,"event":"link","kind":"sim","joint_names":["a"],"channels":[{"name":"robot","joints":[0]}],"period":0.004,"lower":[-1],"upper":[1],"velocity":[0.5],"acceleration":[]})"
      "\n";
  auto run = run_cli({"replay", dir.write("a.jsonl", link).string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find(
                "a.jsonl:1: acceleration: expected an array of 1 numbers or nulls, got []"),
            std::string::npos)
      << run.err;
  std::string fixed = link;
  fixed.replace(fixed.find("[]"), 2, "[1]");
  run = run_cli(
      {"replay",
       dir.write("c.jsonl",
                 fixed + R"({"t":0.004,"event":"command","seq":1,"joints":[0],"measured":[0]})"
                         "\n")
           .string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("c.jsonl:2: channel: missing key"), std::string::npos) << run.err;
}

// The log's size cap: `run` past it rotates the file; each file within the cap, the current
// one replays on its own.
TEST(RunCli, TheSessionLogStaysWithinItsCapAndTheCurrentFileReplays) {
  TempDir dir;
  const auto log = dir.path() / "session.jsonl";
  const auto run = run_sim_with_log(dir, log, {"--log-max-mb", "0.05", "--log-keep", "2"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::uintmax_t cap = 52428;  // 0.05 MiB
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "session.jsonl.3"));
  for (const char* name : {"session.jsonl", "session.jsonl.1", "session.jsonl.2"}) {
    ASSERT_TRUE(std::filesystem::exists(dir.path() / name)) << name;
    EXPECT_LE(std::filesystem::file_size(dir.path() / name), cap) << name;
  }
  const auto replay = run_cli({"replay", log.string()});
  ASSERT_EQ(replay.exit_code, 0) << replay.err << replay.out;
  const auto summary = nlohmann::json::parse(replay.out);
  EXPECT_GT(summary["commands_checked"].get<int>(), 0);
  EXPECT_EQ(summary["counts"]["link"], 1);
  EXPECT_EQ(summary["counts"]["session"], 1);

  const auto bad =
      run_cli({"run", small_yumi_scene(dir).string(), "--targets", lift_targets(dir).string(),
               "--log", log.string(), "--log-max-mb", "0"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--log-max-mb"), std::string::npos) << bad.err;
}

// The first `count` lines of a log (a seed small enough to mutate often).
std::string first_lines(const std::string& text, int count) {
  std::size_t end = 0;
  for (int k = 0; k < count && end != std::string::npos; ++k) end = text.find('\n', end + 1);
  return text.substr(0, end == std::string::npos ? end : end + 1);
}

const test::TextMutator kLogMutator({"{",  "[",     "]",     "}",          ",",     ":",
                                     "\"", "\n",    "1e999", "-1e308",     "1e300", "-1",
                                     "0",  "-0",    "null",  "true",       "\"x\"", "[]",
                                     "{}", "[0.1]", "1e-13", "2147483648", "\xff",  "NaN"});

// issue 32 (item 3): seeded mutations of real logs, one written by `run --log` (the simulated
// robot's link, its commands) and one by the server's optimizer log. Checked in-process as
// `replay` checks them (1000 cases): each is read or refused with an InputError, nothing else;
// then 60 through the CLI: exit 0, 1 or 2, never a signal or 3, and exit 1 names the file.
TEST(ReplayFuzz, MutatedRealLogsAreCheckedOrRefusedNamingTheirLine) {
  TempDir dir;
  const auto run_log = dir.path() / "run.jsonl";
  const auto run = run_sim_with_log(dir, run_log);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto serve_log = dir.path() / "serve.jsonl";
  {
    const auto names = read_session_log(run_log).front().fields.at("joint_names");
    SessionLog log(serve_log);
    log.write_header("session", {{"scene", "scene.json"}, {"joint_names", names}});
    ControllerSnapshot s;
    s.joints = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(names.size()));
    for (int k = 0; k < 5; ++k, s.joints.array() += 0.01) server::log_snapshot(log, s);
  }
  // The run log's first 60 lines, its header (session, link, connect) with 3 commands, so that
  // mutations often reach the link event, and the optimizer log.
  const std::string run_text = test::read_text(run_log);
  const auto header_lines =
      std::count(run_text.begin(), run_text.begin() + run_text.find("\"event\":\"command\""), '\n');
  const std::vector<std::string> seeds = {first_lines(run_text, 60),
                                          first_lines(run_text, static_cast<int>(header_lines) + 3),
                                          test::read_text(serve_log)};
  for (const auto& seed : seeds) {  // the seeds themselves are good logs
    const auto file = dir.write("seed.jsonl", seed);
    const CommandLogCheck check = check_command_log(read_session_log(file), "seed");
    EXPECT_TRUE(check.ok()) << check.violations.front();
    EXPECT_GT(check.commands + check.optimizer_results.size(), 2u);
  }

  const auto file = dir.path() / "fuzz.jsonl";
  const test::FuzzCounts counts =
      test::fuzz_parser(seeds, kLogMutator, 1000, 20261128, [&](const std::string& text) {
        dir.write("fuzz.jsonl", text);
        check_command_log(read_session_log(file), file.string());
      });
  std::cout << "checked: " << counts.parsed << ", refused: " << counts.refused << "\n";
  EXPECT_GT(counts.refused, 250);
  EXPECT_GT(counts.parsed, 100);

  std::mt19937 rng(20261129);
  int exits[3] = {0, 0, 0};
  for (std::size_t c = 0; c < 60; ++c) {
    dir.write("fuzz.jsonl", kLogMutator.mutate(seeds[c % seeds.size()], rng));
    std::vector<std::string> command = {"timeout", "-s", "KILL", "20"};
    for (const auto& word : test::cli_command({"replay", file.string()})) command.push_back(word);
    const auto err = dir.path() / "err.txt";
    const int code = test::wait_for_exit(test::start_process(command, dir.path() / "out.txt", err));
    const std::string message = test::read_text(err);
    ASSERT_TRUE(code == 0 || code == 1 || code == 2) << "case " << c << ": exit " << code << "\n"
                                                     << message.substr(0, 600);
    ++exits[code];
    if (code == 1) {
      EXPECT_NE(message.find("error: " + file.string()), std::string::npos) << message;
    }
  }
  std::cout << "CLI exit 0: " << exits[0] << ", 1: " << exits[1] << ", 2: " << exits[2] << "\n";
  EXPECT_GT(exits[1], 10);
}

}  // namespace
}  // namespace shapectl
