#pragma once
// The default robot link: an in-process SimRobot that follows the commands within its own
// limits, ticked every `sim_period` by a thread. Feedback never goes missing.
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>

#include <shapectl/link/link_supervisor.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/sim_robot.hpp>

namespace shapectl {

class SimLink : public RobotLink {
 public:
  SimLink(const LinkConfig& config, const RobotModel& robot, PoseCheck check,
          std::shared_ptr<SessionLog> log);
  ~SimLink() override;

  void start() override;
  void stop() override;
  void set_target(const Eigen::VectorXd& joints, bool safe) override;
  bool arm(std::string* why_not = nullptr) override;
  void disarm(const std::string& reason) override;
  LinkStatus status() const override;

 private:
  double now() const;
  void run(std::stop_token stop);

  double period_;
  std::shared_ptr<SessionLog> log_;
  std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;  // guards everything below
  LinkSupervisor supervisor_;
  SimRobot robot_;
  std::uint64_t commands_sent_ = 0;
  std::jthread thread_;
};

}  // namespace shapectl
