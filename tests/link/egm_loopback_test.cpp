// The whole EGM chain on loopback: EgmLink (our side) against EgmSimulator (the controller).
#include <gtest/gtest.h>

#include <arpa/inet.h>

#include <numbers>
#include <random>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/egm_simulator.hpp>

#include "link/link_test_support.hpp"

namespace shapectl {
namespace {

using test::sleep_seconds;
using test::wait_until;

constexpr double deg = std::numbers::pi / 180;

ArmJoints chain(double j1, double j2, double j7, double j3, double j4, double j5, double j6) {
  return (ArmJoints() << j1, j2, j7, j3, j4, j5, j6).finished() * deg;
}

LinkConfig fast_config() {
  LinkConfig c;
  c.kind = LinkKind::Egm;
  c.egm_address = "127.0.0.1";
  c.egm_left_port = c.egm_right_port = 0;  // any free ports
  c.max_velocity = 1.0;
  c.max_acceleration = 4.0;
  c.watchdog_timeout = 0.1;
  return c;
}

struct Loopback {
  explicit Loopback(const std::filesystem::path& log_file)
      : robot(test::yumi_arms()),
        log(std::make_shared<SessionLog>(log_file)),
        link(fast_config(), robot, {}, log),
        sim({.left_port = link.port(0),
             .right_port = link.port(1),
             .left_initial = chain(0, -130, 135, 30, 0, 40, 0),
             .right_initial = chain(0, -130, -135, 30, 0, 40, 0)}) {
    link.start();
    sim.start();
  }
  ~Loopback() {
    sim.stop();
    link.stop();
  }
  // The simulated arms' joints in the link's θ order.
  Eigen::VectorXd sim_joints() const {
    Eigen::VectorXd q(14);
    for (int c = 0; c < 2; ++c) {
      const ArmJoints a = sim.stats(c).position;
      for (int i = 0; i < 7; ++i) q[link.channels()[c].joints[i]] = a[i];
    }
    return q;
  }
  RobotModel robot;
  std::shared_ptr<SessionLog> log;
  EgmLink link;
  EgmSimulator sim;
};

TEST(EgmLoopback, ArmedMotionKeepsTheLimitsAndConvergesAndAWatchdogStopsIt) {
  test::TempDir dir;
  const auto log_file = dir.path() / "session.jsonl";
  {
    Loopback lb(log_file);
    ASSERT_TRUE(wait_until([&] { return lb.link.status().connected; }, 2));
    const Eigen::VectorXd start = lb.sim_joints();
    EXPECT_TRUE(lb.link.status().measured.isApprox(start, 1e-12));

    // Not armed: a target does not move the robot.
    Eigen::VectorXd target = start;
    target.array() += 0.25;
    lb.link.set_target(target, true);
    sleep_seconds(0.2);
    EXPECT_EQ(lb.sim_joints(), start);
    EXPECT_FALSE(lb.link.status().armed);

    // Armed: it moves; the target changes on the way; it arrives exactly.
    std::string why;
    ASSERT_TRUE(lb.link.arm(&why)) << why;
    sleep_seconds(0.15);
    target.array() -= 0.4;
    lb.link.set_target(target, true);
    ASSERT_TRUE(wait_until([&] { return lb.link.status().arrived; }, 5));
    // The robot executes the last command one sample later.
    EXPECT_TRUE(wait_until([&] { return lb.sim_joints().isApprox(target, 1e-12); }, 1));
    EXPECT_TRUE(lb.link.status().commanded.isApprox(target, 1e-12));

    // Feedback stops: the link disarms within the watchdog time, naming the reason.
    target.array() += 0.3;
    lb.link.set_target(target, true);
    sleep_seconds(0.05);  // moving now
    lb.sim.set_paused(true);
    const auto paused_at = std::chrono::steady_clock::now();
    ASSERT_TRUE(wait_until([&] { return !lb.link.status().armed; }, 1));
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - paused_at).count();
    EXPECT_LT(took, 0.1 + 0.1);  // watchdog + scheduling slack on a busy machine
    const LinkStatus lost = lb.link.status();
    EXPECT_FALSE(lost.connected);
    EXPECT_NE(lost.reason.find("watchdog"), std::string::npos) << lost.reason;
    sleep_seconds(0.05);
    const Eigen::VectorXd held = lb.sim_joints();

    // Feedback returns: the link commands where the robot is, and nothing moves until re-armed.
    lb.link.set_target(start, true);
    lb.sim.set_paused(false);
    ASSERT_TRUE(wait_until([&] { return lb.link.status().connected; }, 1));
    sleep_seconds(0.3);
    EXPECT_EQ(lb.sim_joints(), held);
    EXPECT_FALSE(lb.link.status().armed);
    ASSERT_TRUE(lb.link.arm(&why)) << why;
    ASSERT_TRUE(wait_until([&] { return lb.link.status().arrived; }, 5));
    EXPECT_TRUE(wait_until([&] { return lb.sim_joints().isApprox(start, 1e-12); }, 1));

    // What the controller received: within the limits, inside the joint limits.
    for (int arm = 0; arm < 2; ++arm) {
      const EgmSimArmStats s = lb.sim.stats(arm);
      EXPECT_GT(s.commands, 100u);
      EXPECT_EQ(s.rejected, 0u);
      EXPECT_EQ(s.outside_limits, 0u);
      EXPECT_LE(s.max_speed, 1.0 + 1e-6);
      EXPECT_LE(s.max_acceleration, 4.0 + 1e-3);
    }
    EXPECT_EQ(lb.link.status().rejected_datagrams, 0u);
  }
  // The whole log: every command within velocity, acceleration and band.
  const auto events = read_session_log(log_file);
  const CommandLogCheck check = check_command_log(events, log_file.string());
  EXPECT_TRUE(check.ok()) << check.violations.front();
  EXPECT_GT(check.commands, 500);
  EXPECT_LE(check.velocity_ratio, 1 + 1e-9);
  EXPECT_LE(check.acceleration_ratio, 1 + 1e-6);
  // The limits were nearly reached: a real test. (Not 1: the legs are short, and on a busy
  // machine the simulator's late ticks look like late feedback, after which the link restarts
  // from rest.)
  EXPECT_GT(check.velocity_ratio, 0.5);
}

TEST(EgmLoopback, BadDatagramsAreCountedAndIgnored) {
  test::TempDir dir;
  Loopback lb(dir.path() / "log.jsonl");
  ASSERT_TRUE(wait_until([&] { return lb.link.status().connected; }, 2));
  std::string why;
  ASSERT_TRUE(lb.link.arm(&why)) << why;

  UdpSocket attacker("127.0.0.1", 0, "test");
  const sockaddr_in left = ipv4_address("127.0.0.1", lb.link.port(0), "test");
  std::mt19937 rng(3);
  EgmCodec codec;
  EgmFeedback valid;
  valid.motors_on = valid.egm_running = valid.rapid_running = true;
  const std::string message(codec.encode_robot(valid));
  std::vector<std::string> bad = {
      std::string(4000, 'x'),                          // oversized
      message.substr(0, 20),                           // truncated
      std::string("\x0a\xff\xff\xff"),                 // malformed length
      std::string(codec.encode_sensor(EgmCommand{})),  // wrong message type
  };
  for (int k = 0; k < 40; ++k) {  // random bytes
    std::string r(1 + rng() % 300, '\0');
    for (auto& c : r) c = static_cast<char>(rng());
    if (!codec.decode_robot(r, valid, nullptr)) bad.push_back(r);
  }
  for (const auto& d : bad) attacker.send_to(d, left);
  ASSERT_TRUE(wait_until([&] { return lb.link.status().rejected_datagrams == bad.size(); }, 2))
      << lb.link.status().rejected_datagrams << " of " << bad.size();
  sleep_seconds(0.05);
  const LinkStatus s = lb.link.status();
  EXPECT_TRUE(s.armed) << s.reason;
  EXPECT_TRUE(s.connected);
  std::array<char, 2048> buffer;
  EXPECT_EQ(attacker.receive(buffer, nullptr), -1);  // no reply to garbage
}

TEST(EgmLoopback, MeasuresTheFeedbackToCommandLatency) {
  test::TempDir dir;
  Loopback lb(dir.path() / "log.jsonl");
  ASSERT_TRUE(wait_until([&] { return lb.link.latency().samples >= 100; }, 3));
  const LatencyStats l = lb.link.latency();
  EXPECT_GT(l.median_us, 0);
  EXPECT_LE(l.median_us, l.p99_us);
  EXPECT_LE(l.p99_us, l.max_us);
}

TEST(EgmArmChannels, MapsYumiJointsToArmsInChainOrder) {
  const RobotModel robot = test::yumi_arms();
  const auto channels = egm_arm_channels(robot);
  ASSERT_EQ(channels.size(), 2u);
  EXPECT_EQ(channels[0].name, "left");
  const auto names = robot.active_joint_names();
  std::vector<std::string> left;
  for (int i : channels[0].joints) left.push_back(names[static_cast<std::size_t>(i)]);
  EXPECT_EQ(left, (std::vector<std::string>{"yumi_joint_1_l", "yumi_joint_2_l", "yumi_joint_7_l",
                                            "yumi_joint_3_l", "yumi_joint_4_l", "yumi_joint_5_l",
                                            "yumi_joint_6_l"}));
}

TEST(EgmArmChannels, RefusesRobotsThatAreNotYumiLike) {
  RobotModel robot = test::yumi_arms();
  robot.set_active_joints({"yumi_joint_1_l", "yumi_joint_2_l"});
  try {
    egm_arm_channels(robot);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("left arm: egm commands whole arms: all 7 joints must be "
                                         "active; missing yumi_joint_7_l"),
              std::string::npos)
        << e.what();
  }
  RobotModel with_gripper = test::yumi_arms();
  with_gripper.set_active_joints({"yumi_joint_1_l", "gripper_l_joint"});
  try {
    egm_arm_channels(with_gripper);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("active joint 'gripper_l_joint'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace shapectl
