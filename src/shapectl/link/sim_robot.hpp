#pragma once
// A stand-in robot: it follows the last command within its own velocity and acceleration
// limits (a MotionGovernor with the robot's limits), one step per sample period.
#include <Eigen/Core>

#include <shapectl/link/motion_governor.hpp>

namespace shapectl {

class SimRobot {
 public:
  // `own_limits`: the robot's band (its hard joint limits), top speeds and accelerations.
  SimRobot(GovernorLimits own_limits, const Eigen::VectorXd& initial);
  void command(const Eigen::VectorXd& joints);  // rad; holds still until the first command
  void step(double dt);                         // seconds
  const Eigen::VectorXd& position() const { return governor_.position(); }

 private:
  MotionGovernor governor_;
  Eigen::VectorXd command_;
  bool has_command_ = false;
};

}  // namespace shapectl
