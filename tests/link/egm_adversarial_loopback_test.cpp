// EgmLink on loopback against a hand-driven controller (two raw UDP sockets, 127.0.0.1):
// bursts after a stall, duplicates, reordering, a second sender. Bounded counts and waits;
// assertions on command values against the limits and the elapsed time as measured here,
// which can only loosen the bound (never on rates).
#include <gtest/gtest.h>

#include <poll.h>

#include <chrono>
#include <numbers>
#include <thread>

#include <shapectl/link/egm_link.hpp>
#include <shapectl/link/motion_pacing.hpp>

#include "link/link_test_support.hpp"

namespace shapectl {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double deg = std::numbers::pi / 180;
constexpr double T = 0.004;
constexpr double v_max = 1.0;

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

LinkConfig config() {
  LinkConfig c;
  c.kind = LinkKind::Egm;
  c.egm_address = "127.0.0.1";
  c.egm_left_port = c.egm_right_port = 0;
  c.max_velocity = v_max;
  c.max_acceleration = 4.0;
  c.watchdog_timeout = 0.5;  // the stalls here stay below it even on a busy machine
  c.egm_period = T;
  return c;
}

// The controller's side, by hand: one socket per arm; each arm follows the last command.
struct Controller {
  explicit Controller(const EgmLink& link) {
    for (int c = 0; c < 2; ++c) {
      sockets.emplace_back("127.0.0.1", 0, "test controller");
      to[c] = ipv4_address("127.0.0.1", link.port(c), "test");
      pose[c] = (ArmJoints() << 0, -130, c ? -135 : 135, 30, 0, 40, 0).finished() * deg;
    }
  }
  std::string datagram(int c, std::uint32_t seqno) {
    EgmFeedback f;
    f.seqno = seqno;
    f.tm = seqno * cycle_ms;
    f.joints = pose[c];
    f.motors_on = f.egm_running = f.rapid_running = true;
    return std::string(codec.encode_robot(f));
  }
  void send(int c, const std::string& bytes) {
    sockets[static_cast<std::size_t>(c)].send_to(bytes, to[c]);
  }
  // Every reply waiting on arm `c`, waiting up to `seconds` for the first `want`.
  std::vector<ArmJoints> replies(int c, std::size_t want, double wait) {
    std::vector<ArmJoints> got;
    const auto end = Clock::now() + std::chrono::duration<double>(wait);
    std::array<char, 2048> buffer;
    while (true) {
      long n;
      while ((n = sockets[static_cast<std::size_t>(c)].receive(buffer, nullptr)) >= 0) {
        EgmCommand cmd;
        if (codec.decode_sensor({buffer.data(), static_cast<std::size_t>(n)}, cmd, nullptr))
          got.push_back(cmd.joints), pose[c] = cmd.joints;
      }
      if (got.size() >= want || Clock::now() > end) return got;
      pollfd p{sockets[static_cast<std::size_t>(c)].fd(), POLLIN, 0};
      ::poll(&p, 1, 1);
    }
  }
  // One cycle on both arms; returns the left arm's reply (empty if none came within 0.2 s).
  std::vector<ArmJoints> cycle() {
    ++seqno;
    for (int c = 0; c < 2; ++c) send(c, datagram(c, seqno));
    auto right = replies(1, 1, 0.2);
    return replies(0, 1, 0.2);
  }

  std::vector<UdpSocket> sockets;
  sockaddr_in to[2]{};
  ArmJoints pose[2];
  EgmCodec codec;
  std::uint32_t seqno = 0;
  std::uint32_t cycle_ms = 4;  // the controller's \SampleRate
};

struct Fixture {
  Fixture() : robot(test::yumi_arms()), link(config(), robot, {}, nullptr), ctl(link) {
    link.start();
  }
  ~Fixture() { link.stop(); }
  // Connects, arms, and gets both arms moving towards a target 0.3 rad away.
  void start_moving() {
    for (int k = 0; k < 5; ++k) ctl.cycle();
    Eigen::VectorXd target = link.status().measured;
    target.array() += 0.3;
    link.set_target(target, true);
    std::string why;
    ASSERT_TRUE(link.arm(&why)) << why;
    run_cycles(60);
  }
  // Cycles on a 4 ms schedule (a late one just comes late).
  void run_cycles(int n) {
    auto next = Clock::now();
    for (int k = 0; k < n; ++k) {
      ctl.cycle();
      next += std::chrono::microseconds(4000);
      std::this_thread::sleep_until(next);
    }
  }
  RobotModel robot;
  EgmLink link;
  Controller ctl;
};

TEST(EgmAdversarial, ABurstAfterAStallAdvancesNoFasterThanTheClock) {
  Fixture f;
  f.start_moving();
  ASSERT_TRUE(f.link.status().armed) << f.link.status().reason;
  const ArmJoints before_stall = f.ctl.pose[0];
  test::sleep_seconds(0.08);  // the network stalls; then 20 datagrams arrive at once
  const auto burst_sent = Clock::now();
  for (int k = 0; k < 20; ++k) {
    ++f.ctl.seqno;
    for (int c = 0; c < 2; ++c) f.ctl.send(c, f.ctl.datagram(c, f.ctl.seqno));
  }
  const std::vector<ArmJoints> replies = f.ctl.replies(0, 20, 1.0);
  const auto burst_answered = Clock::now();
  ASSERT_EQ(replies.size(), 20u);
  // The burst's replies land on one controller tick (or two, should the burst straddle one):
  // one governor step each, not one per datagram (motion_pacing.hpp).
  const double duration = seconds(burst_sent, burst_answered);
  const double bound = v_max * (duration + T) + 1e-9;
  for (const ArmJoints& q : replies)
    EXPECT_LE((q - replies.front()).cwiseAbs().maxCoeff(), bound)
        << "burst took " << duration << " s";
  // The first one restarts from rest after the stall: at most a·T² from the held pose.
  EXPECT_LE((replies.front() - before_stall).cwiseAbs().maxCoeff(), 4.0 * T * T + 1e-12);
  // And motion goes on afterwards: the test was not vacuous.
  f.run_cycles(50);
  EXPECT_GT((f.ctl.pose[0] - replies.back()).cwiseAbs().maxCoeff(), 0.002);
  EXPECT_EQ(f.link.status().stale_datagrams, 0u);
}

TEST(EgmAdversarial, ASecondSenderIsIgnoredGetsNoReplyAndIsCounted) {
  Fixture f;
  f.start_moving();
  UdpSocket intruder("127.0.0.1", 0, "intruder");
  const sockaddr_in left = ipv4_address("127.0.0.1", f.link.port(0), "test");
  for (int k = 0; k < 30; ++k) {
    intruder.send_to(f.ctl.datagram(0, f.ctl.seqno + 100 + static_cast<std::uint32_t>(k)), left);
    const auto reply = f.ctl.cycle();
    ASSERT_EQ(reply.size(), 1u) << "the bound controller still gets its replies";
  }
  ASSERT_TRUE(test::wait_until([&] { return f.link.status().foreign_datagrams == 30; }, 1))
      << f.link.status().foreign_datagrams;
  std::array<char, 2048> buffer;
  EXPECT_EQ(intruder.receive(buffer, nullptr), -1);
  const LinkStatus s = f.link.status();
  EXPECT_TRUE(s.armed) << s.reason;
  EXPECT_EQ(s.stale_datagrams, 0u);  // its sequence numbers did not push the controller's aside
}

TEST(EgmAdversarial, DuplicatesGetNoReplyAndReorderingIsStaleNotLost) {
  Fixture f;
  for (int k = 0; k < 5; ++k) f.ctl.cycle();
  const std::string d = f.ctl.datagram(0, ++f.ctl.seqno);
  f.ctl.send(0, d);
  f.ctl.send(0, d);  // duplicated by the network
  EXPECT_EQ(f.ctl.replies(0, 2, 0.1).size(), 1u);
  // 7 overtakes 6 (a datagram reordered by the network).
  const std::uint32_t s = f.ctl.seqno;
  f.ctl.send(0, f.ctl.datagram(0, s + 2));
  EXPECT_EQ(f.ctl.replies(0, 1, 0.2).size(), 1u);
  f.ctl.send(0, f.ctl.datagram(0, s + 1));
  EXPECT_EQ(f.ctl.replies(0, 1, 0.05).size(), 0u);  // too late to use: no reply
  const LinkStatus st = f.link.status();
  EXPECT_EQ(st.stale_datagrams, 2u);
  EXPECT_EQ(st.lost_datagrams, 0u);
  // A really missing one is lost.
  f.ctl.send(0, f.ctl.datagram(0, s + 4));
  EXPECT_EQ(f.ctl.replies(0, 1, 0.2).size(), 1u);
  EXPECT_EQ(f.link.status().lost_datagrams, 1u);
}

TEST(EgmAdversarial, AControllerCyclingAtAnotherRateThanConfiguredCannotBeArmed) {
  Fixture f;
  f.ctl.cycle_ms = 8;  // \SampleRate 8 ms against egm_period 4 ms: steps would be half speed
  for (int k = 0; k < 5; ++k) f.ctl.cycle();
  std::string why;
  EXPECT_FALSE(f.link.arm(&why));
  EXPECT_NE(why.find("sample period is 8 ms"), std::string::npos) << why;
  EXPECT_NE(why.find("egm_period is 4 ms"), std::string::npos) << why;
  f.ctl.cycle_ms = 4;  // fixed on the controller: arming works
  for (int k = 0; k < 5; ++k) f.ctl.cycle();
  EXPECT_TRUE(f.link.arm(&why)) << why;
}

}  // namespace
}  // namespace shapectl
