// The governor's promises, checked at every step: band, velocity, acceleration, exact landing.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/link/motion_governor.hpp>

namespace shapectl {
namespace {

constexpr double dt = 0.004;
constexpr double slack = 1e-12;

Eigen::VectorXd vec(double a, double b, double c) {
  return (Eigen::VectorXd(3) << a, b, c).finished();
}

GovernorLimits three_joint_limits() {
  return {vec(-1.0, -2.0, -0.5), vec(1.0, 0.5, 3.0), vec(0.5, 1.0, 0.2), vec(1.0, 4.0, 0.5)};
}

// Steps the governor and asserts every limit against the two previous positions.
class Checked {
 public:
  explicit Checked(MotionGovernor& g) : g_(g), prev_(g.position()), prev2_(g.position()) {}
  void towards(const Eigen::VectorXd& target) { g_.step_towards(target, dt), check(); }
  void stop() { g_.step_stop(dt), check(); }

 private:
  void check() {
    const auto& l = g_.limits();
    const Eigen::VectorXd& q = g_.position();
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      ASSERT_LE(std::abs(q[i] - prev_[i]), l.velocity[i] * dt + slack) << "joint " << i;
      ASSERT_LE(std::abs(q[i] - 2 * prev_[i] + prev2_[i]), l.acceleration[i] * dt * dt + slack)
          << "joint " << i;
      ASSERT_GE(q[i], l.lower[i] - slack);
      ASSERT_LE(q[i], l.upper[i] + slack);
    }
    prev2_ = prev_;
    prev_ = q;
  }
  MotionGovernor& g_;
  Eigen::VectorXd prev_, prev2_;
};

TEST(MotionGovernor, LandsExactlyOnTheTargetWithoutOvershoot) {
  MotionGovernor g(three_joint_limits());
  g.reset(vec(-0.9, 0.0, 0.0));
  const Eigen::VectorXd target = vec(0.8, -1.5, 2.0);
  Checked run(g);
  double furthest = -0.9;
  for (int k = 0; k < 10000 && !g.arrived_at(target); ++k) {
    run.towards(target);
    furthest = std::max(furthest, g.position()[0]);
  }
  EXPECT_TRUE(g.arrived_at(target));
  EXPECT_EQ(g.position(), target);
  EXPECT_LE(furthest, 0.8);  // never past the target
}

TEST(MotionGovernor, ReachesTheVelocityLimitOnLongMoves) {
  MotionGovernor g(three_joint_limits());
  g.reset(vec(0, 0, 0));
  Checked run(g);
  double top = 0;
  for (int k = 0; k < 2000; ++k) {
    run.towards(vec(0.9, 0, 0));
    top = std::max(top, g.velocity()[0]);
  }
  EXPECT_DOUBLE_EQ(top, 0.5);
}

TEST(MotionGovernor, ClampsTargetsIntoTheBand) {
  MotionGovernor g(three_joint_limits());
  g.reset(vec(0, 0, 0));
  const Eigen::VectorXd outside = vec(5, -5, 5);
  Checked run(g);
  for (int k = 0; k < 20000 && !g.arrived_at(outside); ++k) run.towards(outside);
  EXPECT_EQ(g.position(), vec(1.0, -2.0, 3.0));
}

TEST(MotionGovernor, RandomTargetChangesKeepEveryLimitAtEveryStep) {
  std::mt19937 rng(42);
  const GovernorLimits limits = three_joint_limits();
  std::uniform_real_distribution<double> unit(0, 1);
  MotionGovernor g(limits);
  g.reset(vec(0, 0, 0));
  Checked run(g);
  Eigen::VectorXd target = vec(0, 0, 0);
  for (int k = 0; k < 200000; ++k) {
    // New targets at random moments, often inside the band's edges and while moving fast.
    if (unit(rng) < 0.01)
      for (int i = 0; i < 3; ++i)
        target[i] = limits.lower[i] - 0.2 + unit(rng) * (limits.upper[i] - limits.lower[i] + 0.4);
    run.towards(target);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(MotionGovernor, StoppingBrakesAtTheAccelerationLimitThenHolds) {
  MotionGovernor g(three_joint_limits());
  g.reset(vec(0, 0, 0));
  Checked run(g);
  for (int k = 0; k < 300; ++k) run.towards(vec(0.9, -1.9, 2.9));
  ASSERT_FALSE(g.at_rest());
  int steps = 0;
  while (!g.at_rest() && steps < 1000) run.stop(), ++steps;
  EXPECT_TRUE(g.at_rest());
  // 0.5 rad/s at 1 rad/s² stops in 0.5 s = 125 samples.
  EXPECT_NEAR(steps, 125, 1);
  const Eigen::VectorXd held = g.position();
  for (int k = 0; k < 10; ++k) run.stop();
  EXPECT_EQ(g.position(), held);
}

TEST(MotionGovernor, StartsFromOutsideTheBandByMovingInwards) {
  MotionGovernor g(three_joint_limits());
  g.reset(vec(1.02, 0, 0));  // the robot stands in the margin
  Eigen::VectorXd prev = g.position();
  for (int k = 0; k < 500; ++k) {
    g.step_towards(vec(2, 0, 0), dt);
    EXPECT_LE(g.position()[0], prev[0]);
    prev = g.position();
  }
  EXPECT_DOUBLE_EQ(g.position()[0], 1.0);
}

}  // namespace
}  // namespace shapectl
