// `serve` stops within 1 s of SIGINT whatever a calibration is doing (issue 32: a calibration
// walking towards a frame's far joints kept it running for more than 30 s). The calibration
// here is an honest slow one: the 12k-tet bar, six frames at distinct poses and markers far
// from the model, a fit that runs to its 30 s limit; the optimizer works on a far target.
#include <signal.h>

#include <chrono>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "server/serve_process.hpp"
#include "support/test_support.hpp"

namespace shapectl::test {
namespace {

using namespace std::chrono_literals;

TEST(ServeStop, SigintStopsTheServerWithinOneSecondWhileACalibrationRuns) {
  TempDir dir;
  ServeProcess server(dir,
                      {"serve", source_path("scenes/yumi_bar_12k.json").string(), "--port", "0"});
  const int port = server.wait_for_port(120s);
  ASSERT_GT(port, 0) << server.log();
  Watcher page(port);
  const std::optional<std::string> scene = page.next("\"type\":\"scene\"", 60s);
  const std::optional<std::string> first = page.next("\"type\":\"state\"", 60s);
  ASSERT_TRUE(scene && first) << server.log();
  const auto names = nlohmann::json::parse(*scene)["robot"]["joint_names"];
  const auto reference = nlohmann::json::parse(*first)["joints"];
  page.send(R"({"type":"set_auto_calibration","on":false,"id":"manual"})");
  ASSERT_TRUE(page.next("\"id\":\"manual\"", 20s));
  // A target far off: the optimizer's steps on this mesh take seconds too.
  page.send(R"({"type":"set_target","id":"target","node":5,"position":[0.4,0.0,0.3]})");
  ASSERT_TRUE(page.next("\"id\":\"target\"", 20s));
  for (std::size_t pose = 0; pose < 6; ++pose) {
    nlohmann::json joints = nlohmann::json::object();
    for (std::size_t j = 0; j < names.size(); ++j)
      joints[names[j].get<std::string>()] = reference[j].get<double>() + (j == pose ? 0.02 : 0);
    nlohmann::json markers = nlohmann::json::array();
    for (int node = 0; node < 20; ++node)
      markers.push_back({{"node", 40 * node}, {"position", {0.4, 0.01 * node, 0.26}}});
    page.send(nlohmann::json{{"type", "observe"},
                             {"id", pose},
                             {"frame", {{"joints", joints}, {"markers", markers}}}}
                  .dump());
    const auto reply = page.next("\"id\":" + std::to_string(pose), 20s);
    ASSERT_TRUE(reply && reply->find("\"ok\"") != std::string::npos) << reply.value_or("none");
  }
  page.send(R"({"type":"calibrate","id":"fit"})");
  const auto started = page.next("\"id\":\"fit\"", 20s);
  ASSERT_TRUE(started && started->find("\"ok\"") != std::string::npos) << started.value_or("none");
  ASSERT_TRUE(page.next("\"running\":true", 20s)) << "the calibration is not running";

  const auto exit = server.signal_and_wait(SIGINT, 30s);
  ASSERT_TRUE(exit) << "still running 30 s after SIGINT\n" << server.log();
  EXPECT_EQ(exit->code, 0) << server.log();
  EXPECT_LT(exit->seconds, 1.0) << server.log();
}

// A page open when serve stops is told so by a close frame (1001, going away), not left to
// find a dead connection (issue 32).
TEST(ServeStop, SigintSendsEveryPageACloseFrame) {
  TempDir dir;
  ServeProcess server(dir, {"serve", source_path("scenes/yumi_bar.json").string(), "--port", "0"});
  const int port = server.wait_for_port(60s);
  ASSERT_GT(port, 0) << server.log();
  Watcher first(port), second(port);
  ASSERT_TRUE(first.next("\"type\":\"state\"", 30s)) << server.log();
  ASSERT_TRUE(second.next("\"type\":\"state\"", 30s)) << server.log();
  const auto exit = server.signal_and_wait(SIGINT, 30s);
  ASSERT_TRUE(exit) << "still running 30 s after SIGINT\n" << server.log();
  EXPECT_EQ(exit->code, 0) << server.log();
  EXPECT_LT(exit->seconds, 1.0) << server.log();
  for (Watcher* page : {&first, &second}) {
    const auto reason = page->close_frame(10s);
    ASSERT_TRUE(reason) << "the connection ended without a close frame";
    EXPECT_EQ(reason->code, boost::beast::websocket::close_code::going_away);
  }
}

}  // namespace
}  // namespace shapectl::test
