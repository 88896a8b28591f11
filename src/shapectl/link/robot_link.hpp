#pragma once
// The link between the optimizer and a robot (simulated or real). The optimizer's current best
// θ goes in as a target; a motion governor inside the link turns it into commands that respect
// velocity/acceleration limits and only move the robot while armed.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace shapectl {

class RobotModel;

struct LinkStatus {
  std::string kind;           // "sim" or "egm"
  bool connected = false;     // feedback is arriving
  bool armed = false;         // commands may move the robot
  double feedback_age = 0;    // seconds since the last feedback (inf if never)
  std::string reason;         // why it is holding or disarmed; empty when all is well
  Eigen::VectorXd measured;   // θ as the robot reports it (active-joint order)
  Eigen::VectorXd commanded;  // θ last commanded
  bool arrived = false;       // armed, at rest on the target, measured within tolerance
  // Armed, at rest short of the target: no step towards it leaves a collision-free stop
  // (`reason` says which pose); a new target frees it.
  bool blocked = false;
  std::uint64_t commands_sent = 0;
  std::uint64_t rejected_datagrams = 0;  // egm: malformed, truncated, oversized, wrong type
  std::uint64_t lost_datagrams = 0;      // egm: controller sequence numbers never received
  std::uint64_t stale_datagrams = 0;     // egm: duplicates, reordered, older than the newest
  std::uint64_t foreign_datagrams = 0;   // egm: from another sender than the bound controller
};

class RobotLink {
 public:
  virtual ~RobotLink() = default;
  virtual void start() = 0;
  virtual void stop() = 0;
  // The optimizer's current best θ (active-joint order of the scene's robot model).
  // `safe` false (colliding, out of limits, non-finite) makes the link hold and disarm.
  virtual void set_target(const Eigen::VectorXd& joints, bool safe) = 0;
  // Explicit arming; false with the reason when not possible (e.g. no feedback).
  virtual bool arm(std::string* why_not = nullptr) = 0;
  virtual void disarm(const std::string& reason) = 0;
  virtual LinkStatus status() const = 0;
};

}  // namespace shapectl
