// `shapectl run`, `egm-sim` and `replay`: the headless chain end to end, exit codes, messages.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <random>

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
  const auto run =
      run_cli({"run", small_yumi_scene(dir).string(), "--targets", lift_targets(dir).string(),
               "--arm", "--until-settled", "--timeout", "60", "--log", log.string()});
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

}  // namespace
}  // namespace shapectl
