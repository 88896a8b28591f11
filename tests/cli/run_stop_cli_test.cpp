// `run --observations-udp` stops within 1 s of SIGINT while an online calibration and an
// optimizer step run (issue 32), and a frame with a joint at 1e6 rad is rejected, not received.
// The 12k-tet bar makes both slow: a fit of six frames runs to its 30 s limit and one
// optimizer step takes seconds.
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <regex>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapectl/link/udp_socket.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using namespace std::chrono_literals;

// The port `run` prints ("run: observations on udp 127.0.0.1:PORT"), or 0 after a minute.
int observation_port(const std::filesystem::path& err) {
  const std::regex line("observations on udp 127\\.0\\.0\\.1:(\\d+)");
  for (int k = 0; k < 1200; ++k) {
    std::smatch m;
    const std::string text = test::read_text(err);
    if (std::regex_search(text, m, line)) return std::stoi(m[1]);
    std::this_thread::sleep_for(50ms);
  }
  return 0;
}

TEST(RunStopCli, SigintStopsWithinOneSecondWhileACalibrationRunsAndFarFramesAreRejected) {
  test::TempDir dir;
  const std::filesystem::path scene_file = test::source_path("scenes/yumi_bar_12k.json");
  const Scene scene = load_scene(scene_file);
  const auto targets =
      dir.write("targets.json", R"({"targets": [{"node": 5, "position": [0.4, 0.0, 0.3]}]})");
  const pid_t pid =
      test::start_process(test::cli_command({"run", scene_file.string(), "--targets",
                                             targets.string(), "--observations-udp", "0"}),
                          dir.path() / "out", dir.path() / "err");
  const int port = observation_port(dir.path() / "err");
  ASSERT_GT(port, 0) << test::read_text(dir.path() / "err");

  // Six frames at distinct poses (the online calibration starts after three), and one far off.
  UdpSocket sender("127.0.0.1", 0, "test sender");
  const sockaddr_in to = ipv4_address("127.0.0.1", port, "test");
  const auto names = scene.robot->model->active_joint_names();
  for (std::size_t pose = 0; pose <= 6; ++pose) {
    nlohmann::json joints = nlohmann::json::object();
    for (std::size_t j = 0; j < names.size(); ++j)
      joints[names[j]] = scene.robot->reference_joints[static_cast<Eigen::Index>(j)] +
                         (j == pose ? (pose == 6 ? 1e6 : 0.02) : 0.0);
    nlohmann::json markers = nlohmann::json::array();
    for (int node = 0; node < 20; ++node)
      markers.push_back({{"node", 40 * node}, {"position", {0.4, 0.01 * node, 0.26}}});
    ASSERT_TRUE(
        sender.send_to(nlohmann::json{{"joints", joints}, {"markers", markers}}.dump(), to));
  }
  std::this_thread::sleep_for(2s);  // the frames taken, the fit and an optimizer step under way

  const auto sent = std::chrono::steady_clock::now();
  kill(pid, SIGINT);
  int status = 0;
  bool exited = false;
  while (!exited && std::chrono::steady_clock::now() < sent + 60s) {
    exited = waitpid(pid, &status, WNOHANG) == pid;
    if (!exited) std::this_thread::sleep_for(2ms);
  }
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - sent;
  if (!exited) kill(pid, SIGKILL), waitpid(pid, &status, 0);
  ASSERT_TRUE(exited) << "still running 60 s after SIGINT";
  EXPECT_LT(took.count(), 1.0) << test::read_text(dir.path() / "err");
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << test::read_text(dir.path() / "err");
  const auto result = nlohmann::json::parse(test::read_text(dir.path() / "out"));
  EXPECT_EQ(result["datagrams"]["received"], 6);
  EXPECT_EQ(result["datagrams"]["rejected"], 1);
  EXPECT_NE(test::read_text(dir.path() / "err")
                .find("joints." + names[6] + ": expected a value within the joint's limits"),
            std::string::npos);
}

}  // namespace
}  // namespace shapectl
