// `shapectl serve` refuses bad input before serving anything: exit 1 and a message saying where.
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl::test {
namespace {

TEST(ServeCli, MissingSceneIsAnInputError) {
  TempDir dir;
  const CliRun r = run_cli({"serve", (dir.path() / "missing.json").string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
}

TEST(ServeCli, SceneWithoutARobotIsAnInputError) {
  const CliRun r =
      run_cli({"serve", source_path("scenes/foam_bar_clamped.json").string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("foam_bar_clamped.json: robot: missing"), std::string::npos) << r.err;
}

TEST(ServeCli, HostMustBeAnAddress) {
  const CliRun r = run_cli({"serve", "--host", "not-an-address", "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--host: expected an IP address, got not-an-address"), std::string::npos)
      << r.err;
}

TEST(ServeCli, WebRootNeedsAnIndexPage) {
  TempDir dir;
  const CliRun r = run_cli({"serve", "--web-root", dir.path().string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--web-root: expected a directory with index.html"), std::string::npos)
      << r.err;
}

TEST(ServeCli, UnknownRobotLinkIsRefused) {
  const CliRun r = run_cli({"serve", "--robot", "warp", "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
}

TEST(ServeCli, LinkOptionOutOfRangeIsAnInputError) {
  const CliRun r = run_cli({"serve", "--robot", "egm", "--max-velocity", "-1", "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("max_velocity: expected a positive number, got -1"), std::string::npos)
      << r.err;
}

// Waits (at most a minute) until `out` shows the URL or the process has exited (left for
// wait_for_exit to collect).
bool wait_for_url(pid_t pid, const std::filesystem::path& out) {
  for (int k = 0; k < 1200; ++k) {
    if (read_text(out).find("open http://") != std::string::npos) return true;
    siginfo_t info{};
    if (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
        info.si_pid == pid)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// The tuning is applied in-process (docs/runtime.md): the program is not run a second time with
// OPENBLAS_THREAD_TIMEOUT added, which /proc shows as the environment the process began with.
TEST(ServeCli, StartsWithoutRestartingItself) {
  TempDir dir;
  const pid_t pid = start_process(cli_command({"serve", "--port", "0"}), dir.path() / "out",
                                  dir.path() / "err", [] { unsetenv("OPENBLAS_THREAD_TIMEOUT"); });
  const bool started = wait_for_url(pid, dir.path() / "out");
  const std::string environment = read_text("/proc/" + std::to_string(pid) + "/environ");
  kill(pid, SIGTERM);
  const int exit_code = wait_for_exit(pid);
  ASSERT_TRUE(started) << read_text(dir.path() / "err");
  EXPECT_EQ(exit_code, 0) << read_text(dir.path() / "err");
  EXPECT_NE(environment.find("PATH="), std::string::npos) << "no environment read";
  EXPECT_EQ(environment.find("OPENBLAS_THREAD_TIMEOUT="), std::string::npos);
}

TEST(ServeCli, EveryLinkOptionOfRunIsTakenAndTheLogReplays) {
  TempDir dir;
  const auto log = dir.path() / "session.jsonl";
  const pid_t pid =
      start_process(cli_command({"serve",     "--port",           "0",         "--robot",
                                 "sim",       "--max-velocity",   "0.3",       "--max-acceleration",
                                 "0.8",       "--limit-margin",   "0.03",      "--watchdog-ms",
                                 "200",       "--egm-address",    "127.0.0.1", "--egm-left-port",
                                 "0",         "--egm-right-port", "0",         "--log",
                                 log.string()}),
                    dir.path() / "out", dir.path() / "err");
  const bool started = wait_for_url(pid, dir.path() / "out");
  kill(pid, SIGTERM);
  const int exit_code = wait_for_exit(pid);
  ASSERT_TRUE(started) << read_text(dir.path() / "err");
  EXPECT_EQ(exit_code, 0) << read_text(dir.path() / "err");

  const CliRun replay = run_cli({"replay", log.string()});
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  const auto summary = nlohmann::json::parse(replay.out);
  EXPECT_EQ(summary["counts"]["session"], 1);
  EXPECT_EQ(summary["violations"].size(), 0u);
  std::istringstream lines(read_text(log));
  std::string line;
  std::getline(lines, line);
  const auto session = nlohmann::json::parse(line);
  EXPECT_EQ(session["command"], "serve");
  EXPECT_NE(session["scene"].get<std::string>().find("yumi_bar.json"), std::string::npos);
  // The link got the options: its logged limits are theirs.
  std::getline(lines, line);
  const auto link = nlohmann::json::parse(line);
  ASSERT_EQ(link["event"], "link");
  for (const auto& a : link["acceleration"]) EXPECT_DOUBLE_EQ(a.get<double>(), 0.8);
  for (const auto& v : link["velocity"]) EXPECT_LE(v.get<double>(), 0.3);
  EXPECT_NEAR(link["lower"][0].get<double>(), -2.94087978961 + 0.03, 1e-12) << "--limit-margin";
}

}  // namespace
}  // namespace shapectl::test
