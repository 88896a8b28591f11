#include <shapectl/link/sim_robot.hpp>

namespace shapectl {

SimRobot::SimRobot(GovernorLimits own_limits, const Eigen::VectorXd& initial)
    : governor_(std::move(own_limits)) {
  governor_.reset(initial);
}

void SimRobot::command(const Eigen::VectorXd& joints) {
  command_ = joints;
  has_command_ = true;
}

void SimRobot::step(double dt) {
  if (has_command_) governor_.step_towards(command_, dt);
}

}  // namespace shapectl
