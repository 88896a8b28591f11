// Real-time pacing of the governor, in simulated time.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/link/motion_pacing.hpp>

namespace shapectl {
namespace {

constexpr double T = 0.004;

TEST(MotionPacer, JitterWithinAQuarterCycleNeverHolds) {
  MotionPacer p(T);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-T / 8, T / 8);  // ±J/2 around the schedule
  for (int k = 0; k < 10000; ++k) {
    const PaceStep s = p.on_send(k * T + jitter(rng));
    ASSERT_TRUE(s.advance) << "cycle " << k;
    ASSERT_FALSE(s.from_rest && k > 0) << "cycle " << k;
  }
}

TEST(MotionPacer, AMissedCycleResumesButAStallRestartsFromRest) {
  MotionPacer p(T);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(p.on_send(k * T).advance);
  const PaceStep missed = p.on_send(11 * T);  // one datagram lost
  EXPECT_TRUE(missed.advance);
  EXPECT_FALSE(missed.from_rest);
  EXPECT_TRUE(p.on_send(11 * T + stall_cycles * T + 1e-6).from_rest);
}

TEST(MotionPacer, ABurstAfterAStallGivesOneStepFromRest) {
  MotionPacer p(T);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(p.on_send(k * T).advance);
  const double after = 9 * T + 0.08;
  const PaceStep first = p.on_send(after);
  EXPECT_TRUE(first.advance);
  EXPECT_TRUE(first.from_rest);
  for (int k = 1; k < 20; ++k) EXPECT_FALSE(p.on_send(after + k * 1e-5).advance) << k;
}

TEST(MotionPacer, NoArrivalPatternAdvancesFasterThanTheClock) {
  // Floods, duplicates with fresh numbers, random gaps: n advances in (t, s] never exceed
  // 1 + (s − t + 2J)/T.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int run = 0; run < 50; ++run) {
    MotionPacer p(T);
    std::vector<double> advances;
    double t = 0;
    for (int k = 0; k < 3000; ++k) {
      const double r = unit(rng);
      t += r < 0.3 ? unit(rng) * 1e-4 : r < 0.9 ? unit(rng) * 2 * T : unit(rng) * 0.05;
      if (p.on_send(t).advance) advances.push_back(t);
    }
    const double J = pacing_jitter(T);
    for (std::size_t i = 0; i < advances.size(); ++i)
      for (std::size_t j = i + 1; j < advances.size() && j < i + 40; ++j) {
        const double n = static_cast<double>(j - i + 1);  // advances in [a_i, a_j]
        ASSERT_LE(n, 1 + (advances[j] - advances[i] + 2 * J) / T + 1e-9) << "run " << run;
      }
    ASSERT_GT(advances.size(), 500u);
  }
}

}  // namespace
}  // namespace shapectl
