#pragma once
// What the simulated and the EGM link share: a LinkSupervisor behind a mutex, the link's own
// clock, and a worker thread that runs the derived link's loop between start() and stop().
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>

#include <shapectl/link/link_supervisor.hpp>
#include <shapectl/link/robot_link.hpp>

namespace shapectl {

class SessionLog;

class SupervisedLink : public RobotLink {
 public:
  void start() override;
  void stop() override;
  void set_target(const Eigen::VectorXd& joints, bool safe) override;
  bool arm(std::string* why_not = nullptr) override;
  void disarm(const std::string& reason) override;

 protected:
  // `period`: the loop's sample time, seconds. `log` may be null.
  SupervisedLink(double period, std::shared_ptr<SessionLog> log, LinkSupervisor supervisor);
  // Derived destructors call stop() first: the loop uses their members.
  ~SupervisedLink() override = default;

  double now() const;  // seconds since construction
  // The loop, on the worker thread, until `stop` is requested.
  virtual void run(std::stop_token stop) = 0;

  const double period_;
  const std::shared_ptr<SessionLog> log_;
  mutable std::mutex mutex_;  // guards the supervisor and the derived link's counters
  LinkSupervisor supervisor_;
  std::uint64_t commands_sent_ = 0;

 private:
  const std::chrono::steady_clock::time_point start_;
  std::jthread thread_;
};

}  // namespace shapectl
