#include <shapectl/robot/joint_limits.hpp>

#include <algorithm>
#include <cassert>

namespace shapectl {

JointLimits::JointLimits(const RobotModel& model, double margin, double stiffness)
    : JointLimits(model.lower_limits(), model.upper_limits(), margin, stiffness) {}

double joint_margin(double lower, double upper, double margin) {
  return std::min(margin, 0.25 * (upper - lower));  // infinite limits: margin
}

JointLimits::JointLimits(Eigen::VectorXd lower, Eigen::VectorXd upper, double margin,
                         double stiffness)
    : lower_(lower), upper_(upper), margin_(margin), barrier_{stiffness} {
  assert(lower_.size() == upper_.size() && margin >= 0 && stiffness >= 0);
  for (int i = 0; i < lower_.size(); ++i) {
    const double m = joint_margin(lower[i], upper[i], margin);
    lower_[i] += m;
    upper_[i] -= m;
  }
}

double JointLimits::value(const Eigen::VectorXd& joints, Eigen::VectorXd* gradient) const {
  assert(joints.size() == size());
  if (gradient) gradient->setZero(size());
  double total = 0;
  for (int i = 0; i < size(); ++i) {
    // Infinite limits give v = -inf: the barrier is zero there.
    const double below = lower_[i] - joints[i];
    const double above = joints[i] - upper_[i];
    total += barrier_.value(below) + barrier_.value(above);
    if (gradient) (*gradient)[i] = barrier_.derivative(above) - barrier_.derivative(below);
  }
  return total;
}

void JointLimits::residuals(const Eigen::VectorXd& joints, Eigen::VectorXd& r,
                            Eigen::MatrixXd* jacobian) const {
  assert(joints.size() == size());
  r.resize(2 * size());
  if (jacobian) jacobian->setZero(2 * size(), size());
  for (int i = 0; i < size(); ++i) {
    const double below = lower_[i] - joints[i];
    const double above = joints[i] - upper_[i];
    r[2 * i] = barrier_.residual(below);
    r[2 * i + 1] = barrier_.residual(above);
    if (jacobian) {
      (*jacobian)(2 * i, i) = -barrier_.residual_derivative(below);
      (*jacobian)(2 * i + 1, i) = barrier_.residual_derivative(above);
    }
  }
}

std::vector<LimitViolation> limit_violations(const RobotModel& model,
                                             const Eigen::VectorXd& joints) {
  std::vector<LimitViolation> out;
  for (int j = 0; j < model.joint_count(); ++j) {
    const Joint& joint = model.joints()[static_cast<std::size_t>(j)];
    if (!joint.movable()) continue;
    if (joints[j] < joint.lower || joints[j] > joint.upper)
      out.push_back({joint.name, joints[j], joint.lower, joint.upper});
  }
  return out;
}

}  // namespace shapectl
