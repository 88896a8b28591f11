#include <shapectl/link/sim_link.hpp>

#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

namespace {

// The simulated robot's own limits: its hard joint limits, URDF speeds, sim acceleration.
GovernorLimits sim_robot_limits(const LinkConfig& config, const RobotModel& robot,
                                const GovernorLimits& governor) {
  GovernorLimits own{robot.lower_limits(), robot.upper_limits(), robot.velocity_limits(),
                     Eigen::VectorXd::Constant(robot.active_count(), config.sim_acceleration)};
  // A joint without a URDF speed moves at the governor's speed at most.
  own.velocity = (own.velocity.array().isFinite() && own.velocity.array() > 0)
                     .select(own.velocity, governor.velocity);
  own.acceleration = own.acceleration.cwiseMax(governor.acceleration);
  return own;
}

Eigen::VectorXd sim_initial(const LinkConfig& config, const RobotModel& robot) {
  if (config.sim_initial_joints.size() == robot.active_count()) return config.sim_initial_joints;
  return Eigen::VectorXd::Zero(robot.active_count())
      .cwiseMax(robot.lower_limits())
      .cwiseMin(robot.upper_limits());
}

}  // namespace

SimLink::SimLink(const LinkConfig& config, const RobotModel& robot, PoseCheck check,
                 std::shared_ptr<SessionLog> log)
    : SupervisedLink(config.sim_period, log,
                     LinkSupervisor(to_string(LinkKind::Sim), robot.active_joint_names(),
                                    {{"robot",
                                      [&] {
                                        std::vector<int> all(
                                            static_cast<std::size_t>(robot.active_count()));
                                        for (int i = 0; i < robot.active_count(); ++i)
                                          all[static_cast<std::size_t>(i)] = i;
                                        return all;
                                      }()}},
                                    robot.lower_limits(), robot.upper_limits(),
                                    governor_limits(config, robot),
                                    {config.watchdog_timeout, config.max_tracking_error,
                                     config.arrive_tolerance, config.sim_period},
                                    std::move(check), log.get())),
      robot_(sim_robot_limits(config, robot, supervisor_.limits()), sim_initial(config, robot)) {
  if (log_)
    log_link_started(*log_, to_string(LinkKind::Sim), robot.active_joint_names(),
                     supervisor_.channels(), supervisor_.limits(), period_);
}

SimLink::~SimLink() { stop(); }

void SimLink::run(std::stop_token stop) {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(period_));
  auto next = std::chrono::steady_clock::now();
  Eigen::VectorXd command, measured;
  while (!stop.stop_requested()) {
    next += period;
    std::this_thread::sleep_until(next);
    std::uint64_t seq = 0;
    FeedbackStep step;
    {
      std::lock_guard lock(mutex_);
      robot_.step(period_);
      measured = robot_.position();
      // The simulated robot is its own controller: stamped now, the reply lands at its next tick.
      const double t = now();
      step = supervisor_.on_feedback(0, measured, {}, t, t);
      if (step.send) {
        command = supervisor_.command(0);
        robot_.command(command);
        seq = ++commands_sent_;
      }
    }
    if (log_ && step.send) log_command(*log_, "robot", seq, command, measured, step);
  }
}

LinkStatus SimLink::status() const {
  std::lock_guard lock(mutex_);
  LinkStatus s = supervisor_.status(now());
  s.commands_sent = commands_sent_;
  return s;
}

}  // namespace shapectl
