// Robot link benchmarks: EGM codec, governor step, and the time from a feedback datagram's
// arrival to its command leaving, at 250 Hz on loopback (the number that matters: EGM's sample
// period is 4 ms and the reply should take a tiny fraction of it).
#include <benchmark/benchmark.h>

#include <poll.h>

#include <chrono>
#include <thread>

#include <shapectl/link/egm_codec.hpp>
#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/motion_governor.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {
namespace {

RobotModel yumi_arms() {
  RobotModel robot =
      RobotModel::load_urdf_file(std::string(SHAPECTL_SOURCE_DIR) + "/data/robots/yumi/yumi.urdf");
  std::vector<std::string> names;
  for (const char* arm : {"l", "r"})
    for (int axis : {1, 2, 7, 3, 4, 5, 6})
      names.push_back("yumi_joint_" + std::to_string(axis) + "_" + arm);
  robot.set_active_joints(names);
  return robot;
}

EgmFeedback sample_feedback(std::uint32_t seqno) {
  EgmFeedback f;
  f.seqno = seqno;
  f.tm = seqno * 4;  // the controller's clock, ms: one 4 ms cycle per datagram
  f.joints << 0.1, -1.2, 0.8, 0.5, -0.3, 0.4, 0.2;
  f.motors_on = f.egm_running = f.rapid_running = true;
  return f;
}

void BM_EgmDecodeRobot(benchmark::State& state) {
  EgmCodec codec;
  const std::string bytes(codec.encode_robot(sample_feedback(1)));
  EgmFeedback f;
  for (auto _ : state) benchmark::DoNotOptimize(codec.decode_robot(bytes, f, nullptr));
}
BENCHMARK(BM_EgmDecodeRobot);

void BM_EgmEncodeSensor(benchmark::State& state) {
  EgmCodec codec;
  EgmCommand c;
  c.joints = sample_feedback(1).joints;
  for (auto _ : state) benchmark::DoNotOptimize(codec.encode_sensor(c).size());
}
BENCHMARK(BM_EgmEncodeSensor);

void BM_GovernorStepYumi(benchmark::State& state) {
  const RobotModel robot = yumi_arms();
  MotionGovernor g(governor_limits(LinkConfig{}, robot));
  g.reset(Eigen::VectorXd::Zero(14));
  Eigen::VectorXd a = Eigen::VectorXd::Constant(14, 0.3), b = -a;
  int k = 0;
  for (auto _ : state) {
    g.step_towards((++k / 500) % 2 ? a : b, 0.004);
    benchmark::DoNotOptimize(g.position().data());
  }
}
BENCHMARK(BM_GovernorStepYumi);

// One controller-side socket sends an EgmRobot every 4 ms to the left arm's port and waits for
// the reply. Manual time = round trip; counters = the link's own receive→send time.
void BM_EgmFeedbackToCommand(benchmark::State& state) {
  const RobotModel robot = yumi_arms();
  LinkConfig config;
  config.kind = LinkKind::Egm;
  config.egm_address = "127.0.0.1";
  config.egm_left_port = config.egm_right_port = 0;
  EgmLink link(config, robot, {}, nullptr);
  link.start();
  UdpSocket controller("127.0.0.1", 0, "bench");
  const sockaddr_in left = ipv4_address("127.0.0.1", link.port(0), "bench");
  EgmCodec codec;
  std::array<char, 2048> reply;
  std::uint32_t seqno = 0;
  auto next = std::chrono::steady_clock::now();
  for (auto _ : state) {
    next += std::chrono::microseconds(4000);
    std::this_thread::sleep_until(next);
    const std::string bytes(codec.encode_robot(sample_feedback(++seqno)));
    const auto sent = std::chrono::steady_clock::now();
    controller.send_to(bytes, left);
    pollfd fd{controller.fd(), POLLIN, 0};
    while (controller.receive(reply, nullptr) < 0) ::poll(&fd, 1, 100);
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count());
  }
  const LatencyStats l = link.latency();
  state.counters["link_median_us"] = l.median_us;
  state.counters["link_p99_us"] = l.p99_us;
  state.counters["link_max_us"] = l.max_us;
  link.stop();
}
BENCHMARK(BM_EgmFeedbackToCommand)
    ->UseManualTime()
    ->Iterations(2500)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace shapectl

BENCHMARK_MAIN();
