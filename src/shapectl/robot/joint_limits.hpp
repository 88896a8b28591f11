#pragma once
// Joint limits as two one-sided barriers per active joint, active inside a margin (per joint:
// joint_margin below):
//   lower: v = (lower + margin) − θ,   upper: v = θ − (upper − margin),   each CubicBarrier.
// Continuous joints (infinite limits) get none.
#include <string>
#include <vector>

#include <shapectl/robot/cubic_barrier.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

// The margin a joint keeps from each of its limits: `margin`, but at most a quarter of its
// range, so a short joint (a 25 mm gripper finger under a 0.05 margin) keeps half its range
// free instead of being pinned at its middle.
double joint_margin(double lower, double upper, double margin);

class JointLimits {
 public:
  // Limits of the model's active joints; margin in the joints' units (rad or m), >= 0.
  JointLimits(const RobotModel& model, double margin, double stiffness);
  JointLimits(Eigen::VectorXd lower, Eigen::VectorXd upper, double margin, double stiffness);

  int size() const { return static_cast<int>(lower_.size()); }  // number of active joints
  double margin() const { return margin_; }
  double stiffness() const { return barrier_.stiffness; }

  // Σ barriers at θ; `gradient` (size n, overwritten) may be null.
  double value(const Eigen::VectorXd& joints, Eigen::VectorXd* gradient = nullptr) const;
  // Residuals, 2 per joint [lower_0, upper_0, lower_1, …] so ½|r|² = value; `jacobian`
  // (2n × n, overwritten) may be null.
  void residuals(const Eigen::VectorXd& joints, Eigen::VectorXd& r,
                 Eigen::MatrixXd* jacobian = nullptr) const;

 private:
  Eigen::VectorXd lower_;  // already moved inwards by the margin
  Eigen::VectorXd upper_;
  double margin_;
  CubicBarrier barrier_;
};

// A joint outside its hard limits (no margin): for reports.
struct LimitViolation {
  std::string joint;
  double value;
  double lower;
  double upper;
};
// Every movable joint of `joints` (size model.joint_count(), see RobotModel::full_joints).
std::vector<LimitViolation> limit_violations(const RobotModel& model,
                                             const Eigen::VectorXd& joints);

}  // namespace shapectl
