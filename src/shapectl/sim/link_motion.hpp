#pragma once
// The robot's links moving along the straight joint path θ(s) = θ0 + s (θ1 − θ0), s ∈ [0, 1],
// for the CCD of the obstacles on them (ObstacleContact::max_obstacle_step).
//
// The travel bound. A point p on a link moves at |dp/ds| ≤ V(s) = Σ_j ω_j r_j(s) + Σ_k ω_k
// over the revolute joints j and prismatic joints k between the root and the link, ω the
// joint's rate |dθ_j/ds| (mimic factor included) and r_j = |p − o_j| its distance from a point
// o_j on joint j's axis. r_j changes only with the joints below j (those above move p and o_j
// rigidly together; j itself turns p about o_j), each by at most its share of V, so
// dr_j/ds ≤ V and dV/ds ≤ Ω V with Ω = Σ_j ω_j (revolute). Hence V(s + τ) ≤ V(s) e^{Ωτ} and
// the travel over [s, s + h] is at most V(s) (e^{Ωh} − 1) / Ω: a true bound however the arm
// turns, not a linearisation.
#include <shapectl/contact/obstacle_motion.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {

class LinkMotion : public ObstacleMotion {
 public:
  LinkMotion(const RobotModel& robot, const Eigen::VectorXd& from, const Eigen::VectorXd& to);

  void move_to(double s) override;
  const Eigen::Isometry3d& displacement(int link) const override { return displacement_[link]; }
  double time_to_travel(int link, const Vec3& p, double distance) const override;
  double travel(int link, const Vec3& p, double h) const override;

  // The links' poses at the current s.
  const KinematicsState& kinematics() const { return state_; }

 private:
  // V and Ω (above) for a point on `link` at p, now.
  std::pair<double, double> rates(int link, const Vec3& p) const;

  const RobotModel& robot_;
  Eigen::VectorXd from_, step_;
  KinematicsState state_;
  std::vector<Eigen::Isometry3d> start_inverse_;  // T_world_link(θ0)⁻¹
  std::vector<Eigen::Isometry3d> displacement_;   // T_world_link(θ(s)) T_world_link(θ0)⁻¹
};

}  // namespace shapectl
