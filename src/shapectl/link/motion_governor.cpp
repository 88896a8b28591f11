#include <shapectl/link/motion_governor.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>

namespace shapectl {

namespace {

// The braking curve is planned with this fraction of the acceleration limit: the last,
// fractional step of a stop needs up to 9/8 of the planned deceleration, so planning with
// 8/9 keeps every step within the limit and the landing exact.
constexpr double plan_fraction = 8.0 / 9.0;

// Fastest speed from which braking by a·dt per sample stops within `distance` (≥ 0):
// n samples of speed n·a·dt, (n−1)·a·dt, … cover a·dt²·n(n+1)/2.
double stopping_speed(double distance, double a, double dt) {
  const double n = std::sqrt(0.25 + 2 * distance / (a * dt * dt)) - 0.5;
  return n * a * dt;
}

}  // namespace

GovernorLimits GovernorLimits::subset(const std::vector<int>& joints) const {
  GovernorLimits s;
  const auto n = static_cast<Eigen::Index>(joints.size());
  s.lower.resize(n), s.upper.resize(n), s.velocity.resize(n), s.acceleration.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int j = joints[static_cast<std::size_t>(i)];
    s.lower[i] = lower[j], s.upper[i] = upper[j];
    s.velocity[i] = velocity[j], s.acceleration[i] = acceleration[j];
  }
  return s;
}

MotionGovernor::MotionGovernor(GovernorLimits limits) : limits_(std::move(limits)) {
  assert(limits_.lower.size() == limits_.velocity.size());
  assert((limits_.velocity.array() > 0).all() && (limits_.acceleration.array() > 0).all());
  position_ = clamp_to_band(Eigen::VectorXd::Zero(limits_.size()));
  velocity_ = Eigen::VectorXd::Zero(limits_.size());
}

void MotionGovernor::reset(const Eigen::VectorXd& position) {
  assert(position.size() == limits_.size() && position.allFinite());
  position_ = position;
  velocity_.setZero();
}

Eigen::VectorXd MotionGovernor::clamp_to_band(const Eigen::VectorXd& joints) const {
  return joints.cwiseMax(limits_.lower).cwiseMin(limits_.upper);
}

void MotionGovernor::step_towards(const Eigen::VectorXd& target, double dt) {
  assert(target.size() == limits_.size() && dt > 0);
  const Eigen::VectorXd goal = clamp_to_band(target);
  for (Eigen::Index i = 0; i < goal.size(); ++i) {
    const double a = limits_.acceleration[i];
    const double error = goal[i] - position_[i];
    const double distance = std::abs(error);
    // Wanted speed: as fast as allowed, but able to stop at the goal, and landing on it.
    const double speed = std::min(
        {limits_.velocity[i], stopping_speed(distance, plan_fraction * a, dt), distance / dt});
    const double wanted = std::copysign(speed, error);
    const double v = std::clamp(wanted, velocity_[i] - a * dt, velocity_[i] + a * dt);
    velocity_[i] = v;
    // Landing exactly (no rounding residue), else integrate.
    position_[i] = (v == wanted && speed == distance / dt) ? goal[i] : position_[i] + v * dt;
  }
}

void MotionGovernor::step_stop(double dt) {
  assert(dt > 0);
  for (Eigen::Index i = 0; i < velocity_.size(); ++i) {
    const double dv = limits_.acceleration[i] * dt;
    const double v = velocity_[i];
    velocity_[i] = std::abs(v) <= dv ? 0.0 : v - std::copysign(dv, v);
    position_[i] += velocity_[i] * dt;
  }
}

bool MotionGovernor::arrived_at(const Eigen::VectorXd& target) const {
  return at_rest() && position_ == clamp_to_band(target);
}

}  // namespace shapectl
