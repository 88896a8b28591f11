#pragma once
// The default robot link: an in-process SimRobot that follows the commands within its own
// limits, ticked every `sim_period` by a thread. Feedback never goes missing.
#include <memory>

#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/sim_robot.hpp>
#include <shapectl/link/supervised_link.hpp>

namespace shapectl {

class SimLink : public SupervisedLink {
 public:
  SimLink(const LinkConfig& config, const RobotModel& robot, PoseCheck check,
          std::shared_ptr<SessionLog> log);
  ~SimLink() override;

  LinkStatus status() const override;

 private:
  void run(std::stop_token stop) override;

  SimRobot robot_;  // guarded by mutex_
};

}  // namespace shapectl
