#include <shapectl/link/supervised_link.hpp>

namespace shapectl {

SupervisedLink::SupervisedLink(double period, std::shared_ptr<SessionLog> log,
                               LinkSupervisor supervisor)
    : period_(period),
      log_(std::move(log)),
      supervisor_(std::move(supervisor)),
      start_(std::chrono::steady_clock::now()) {}

double SupervisedLink::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void SupervisedLink::start() {
  if (!thread_.joinable()) thread_ = std::jthread([this](std::stop_token s) { run(s); });
}

void SupervisedLink::stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  thread_.join();
}

void SupervisedLink::set_target(const Eigen::VectorXd& joints, bool safe) {
  const std::string problem = supervisor_.target_problem(joints, safe);
  std::lock_guard lock(mutex_);
  supervisor_.set_target(joints, problem);
}

bool SupervisedLink::arm(std::string* why_not) {
  std::lock_guard lock(mutex_);
  return supervisor_.arm(now(), why_not);
}

void SupervisedLink::disarm(const std::string& reason) {
  std::lock_guard lock(mutex_);
  supervisor_.disarm(reason);
}

}  // namespace shapectl
