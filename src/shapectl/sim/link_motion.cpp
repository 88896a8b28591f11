#include <shapectl/sim/link_motion.hpp>

#include <cmath>
#include <limits>

namespace shapectl {

LinkMotion::LinkMotion(const RobotModel& robot, const Eigen::VectorXd& from,
                       const Eigen::VectorXd& to)
    : robot_(robot), from_(from), step_(to - from) {
  forward_kinematics(robot_, from_, state_);
  for (const Eigen::Isometry3d& T : state_.T_world_link) start_inverse_.push_back(T.inverse());
  displacement_.assign(start_inverse_.size(), Eigen::Isometry3d::Identity());
}

void LinkMotion::move_to(double s) {
  forward_kinematics(robot_, from_ + s * step_, state_);
  for (std::size_t l = 0; l < displacement_.size(); ++l)
    displacement_[l] = state_.T_world_link[l] * start_inverse_[l];
}

std::pair<double, double> LinkMotion::rates(int link, const Vec3& p) const {
  double speed = 0, growth = 0;
  for (const RobotModel::JacobianEntry& e : robot_.jacobian_entries(link)) {
    const double rate = std::abs(e.scale * step_[e.column]);
    if (robot_.joints()[e.joint].type == JointType::Prismatic) {
      speed += rate;
    } else {
      speed += rate * (p - state_.joint_origins_world[e.joint]).norm();
      growth += rate;
    }
  }
  return {speed, growth};
}

double LinkMotion::travel(int link, const Vec3& p, double h) const {
  const auto [speed, growth] = rates(link, p);
  return growth > 0 ? speed * std::expm1(growth * h) / growth : speed * h;
}

double LinkMotion::time_to_travel(int link, const Vec3& p, double distance) const {
  const auto [speed, growth] = rates(link, p);
  if (!(speed > 0)) return std::numeric_limits<double>::infinity();
  return growth > 0 ? std::log1p(growth * distance / speed) / growth : distance / speed;
}

}  // namespace shapectl
