// Pacing of the governor by the controller ticks that replies land on, in simulated time.
// The controller ticks at kT and stamps its feedback kT; a datagram arrives `latency` later.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <shapectl/link/motion_pacing.hpp>

namespace shapectl {
namespace {

constexpr double T = 0.004;
constexpr double fastest = 1e-4;  // the network's fastest datagram, s

// Which tick (index) a controller time falls on, for readable assertions.
int tick_of(double controller_time) { return static_cast<int>(std::lround(controller_time / T)); }

TEST(MotionPacer, OnTimeFeedbackAdvancesOncePerTickAndNeverWaits) {
  MotionPacer p(T);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> latency(fastest, 5 * fastest);
  for (int k = 1; k < 10000; ++k) {
    const double now = k * T + latency(rng);
    const PaceStep s = p.on_feedback(now, k * T);
    ASSERT_TRUE(s.advance) << "cycle " << k;
    ASSERT_EQ(s.from_rest, k == 1) << "cycle " << k;
    ASSERT_EQ(s.send_at, now) << "cycle " << k;
    ASSERT_EQ(tick_of(s.lands_at), k + 1) << "cycle " << k;
  }
}

TEST(MotionPacer, ALateReplyStillLandingOnItsTickAdvancesAndSoDoesTheNextOnTimeOne) {
  MotionPacer p(T);
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(p.on_feedback(k * T + fastest, k * T).advance);
  const PaceStep late = p.on_feedback(11 * T + 3e-3, 11 * T);  // 3 ms late, before tick 12
  EXPECT_TRUE(late.advance);
  EXPECT_FALSE(late.from_rest);
  EXPECT_EQ(tick_of(late.lands_at), 12);
  const PaceStep next = p.on_feedback(12 * T + fastest, 12 * T);  // 2.9 ms later
  EXPECT_TRUE(next.advance);
  EXPECT_FALSE(next.from_rest);
  EXPECT_EQ(tick_of(next.lands_at), 13);
}

TEST(MotionPacer, AReplyPastItsTickLeavesThatTickHeldAndRestartsFromRest) {
  MotionPacer p(T);
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(p.on_feedback(k * T + fastest, k * T).advance);
  // Feedback 11 arrives after tick 12: tick 12 keeps command 10's pose, 11's lands on 13.
  const PaceStep late = p.on_feedback(12 * T + 1e-3, 11 * T);
  EXPECT_TRUE(late.advance);
  EXPECT_TRUE(late.from_rest);
  EXPECT_EQ(tick_of(late.lands_at), 13);
  // Feedback 12, on time, lands on 13 too: it repeats the command.
  const PaceStep same = p.on_feedback(12 * T + 1.5e-3, 12 * T);
  EXPECT_FALSE(same.advance);
  EXPECT_EQ(tick_of(same.lands_at), 13);
  const PaceStep next = p.on_feedback(13 * T + fastest, 13 * T);
  EXPECT_TRUE(next.advance);
  EXPECT_FALSE(next.from_rest);
}

TEST(MotionPacer, ABurstAfterAStallGivesOneStepFromRest) {
  MotionPacer p(T);
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(p.on_feedback(k * T + fastest, k * T).advance);
  const double after = 10 * T + 0.08 + 1e-3;  // feedback 11..30 held 80 ms, then all at once
  int advanced = 0;
  for (int k = 11; k <= 30; ++k) {
    const PaceStep s = p.on_feedback(after + (k - 11) * 1e-6, k * T);
    advanced += s.advance;
    if (k == 11) {
      EXPECT_TRUE(s.advance && s.from_rest);
    }
    EXPECT_EQ(tick_of(s.lands_at), 31) << k;
  }
  EXPECT_EQ(advanced, 1);
}

TEST(MotionPacer, AReplyThatCouldLandOnEitherSideOfATickWaitsUntilItCannot) {
  MotionPacer p(T);
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(p.on_feedback(k * T + fastest, k * T).advance);
  // Feedback 11 arrives 0.2 ms before tick 12 (controller time, from the fastest datagram):
  // a reply might reach the controller before or after that tick.
  const double now = 12 * T + fastest - 2e-4;
  const PaceStep s = p.on_feedback(now, 11 * T);
  EXPECT_NEAR(s.send_at, 12 * T + fastest, 1e-6);  // sent when tick 12 has surely passed (the
  // offset estimate rose by the allowed drift meanwhile)
  EXPECT_EQ(tick_of(s.lands_at), 13);
  EXPECT_TRUE(s.advance && s.from_rest);  // tick 12 holds command 10's pose
  // The next reply cannot overtake it.
  EXPECT_GE(p.on_feedback(now + 1e-5, 12 * T).send_at, s.send_at);
}

TEST(MotionPacer, NoStampsAdvanceFasterThanTheClock) {
  // Floods, stamps running ahead, random gaps: n advances in [a_i, a_j] never exceed
  // 1 + (a_j − a_i + 2T)/T (the credit: capped at 2T, spent down to −T).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int run = 0; run < 50; ++run) {
    MotionPacer p(T);
    std::vector<double> advances;
    double t = 0, stamp = 0;
    for (int k = 0; k < 3000; ++k) {
      const double r = unit(rng);
      t += r < 0.3 ? unit(rng) * 1e-4 : r < 0.9 ? unit(rng) * 2 * T : unit(rng) * 0.05;
      stamp += T * (1 + static_cast<int>(unit(rng) * 30));
      const PaceStep s = p.on_feedback(t, stamp);
      if (s.advance) advances.push_back(s.send_at);
    }
    for (std::size_t i = 0; i < advances.size(); ++i)
      for (std::size_t j = i + 1; j < advances.size() && j < i + 40; ++j) {
        const double n = static_cast<double>(j - i + 1);
        ASSERT_LE(n, 1 + (advances[j] - advances[i] + 2 * T) / T + 1e-9) << "run " << run;
      }
    ASSERT_GT(advances.size(), 500u);
  }
}

TEST(MotionPacer, FollowsAControllerClockThatRunsSlow) {
  // 80 ppm slower than ours (the offset estimate rises by up to 100 ppm): after ten minutes
  // replies still land one per tick without waiting.
  MotionPacer p(T);
  for (int k = 1; k <= 150000; ++k) {
    const double now = k * T * (1 + 80e-6) + fastest;
    const PaceStep s = p.on_feedback(now, k * T);
    ASSERT_TRUE(s.advance) << k;
    ASSERT_EQ(s.send_at, now) << k;
  }
}

}  // namespace
}  // namespace shapectl
