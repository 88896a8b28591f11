#pragma once
// Turns a target θ into a stream of commanded positions, one per sample of dt seconds, that
// never leave the joint band and never exceed the per-joint velocity and acceleration limits:
//   |q[k] − q[k−1]| ≤ v·dt,  |q[k] − 2q[k−1] + q[k−2]| ≤ a·dt²,  lower ≤ q[k] ≤ upper
// (the last once q is inside the band; from outside it only moves inwards).
// It brakes along a discrete stopping curve, so it lands on the target without overshoot.
#include <vector>

#include <Eigen/Core>

namespace shapectl {

struct GovernorLimits {
  Eigen::VectorXd lower, upper;  // rad; the band commands stay in (joint limits − margin)
  Eigen::VectorXd velocity;      // rad/s, > 0
  Eigen::VectorXd acceleration;  // rad/s², > 0
  int size() const { return static_cast<int>(velocity.size()); }
  // The limits of some joints, in the order of `joints` (indices into this).
  GovernorLimits subset(const std::vector<int>& joints) const;
};

class MotionGovernor {
 public:
  explicit MotionGovernor(GovernorLimits limits);

  const GovernorLimits& limits() const { return limits_; }
  // Standstill at `position` (e.g. where the robot is measured to be).
  void reset(const Eigen::VectorXd& position);
  // One sample towards `target` (clamped into the band). `dt` > 0, seconds.
  void step_towards(const Eigen::VectorXd& target, double dt);
  // Velocity to zero at once, position kept: the robot's reference already stood still
  // (its controller held our last command through a feedback gap).
  void halt() { velocity_.setZero(); }
  // One sample of braking to a standstill, at the acceleration limit; then it holds.
  void step_stop(double dt);

  const Eigen::VectorXd& position() const { return position_; }  // rad
  const Eigen::VectorXd& velocity() const { return velocity_; }  // rad/s
  bool at_rest() const { return (velocity_.array() == 0).all(); }
  // At rest exactly on `target` clamped into the band.
  bool arrived_at(const Eigen::VectorXd& target) const;
  Eigen::VectorXd clamp_to_band(const Eigen::VectorXd& joints) const;

 private:
  GovernorLimits limits_;
  Eigen::VectorXd position_;
  Eigen::VectorXd velocity_;
};

}  // namespace shapectl
