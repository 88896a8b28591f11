#pragma once
// The safety logic shared by every robot link, free of threads and sockets so it can be tested
// step by step: it validates targets, owns the armed state, runs one MotionGovernor per
// channel (an EGM arm, or the whole robot) and the feedback watchdog.
//
// Rules:
// - Commands start from the measured position: a channel's governor is reset to the measured
//   joints when its feedback (re)appears, and at arming if it stands still.
// - Motion towards the target only while armed; otherwise the governor brakes to a standstill
//   at the acceleration limit and holds.
// - Disarm (with a reason) on: an unsafe target (flagged, non-finite, outside the joint limits,
//   failing the pose check), feedback missing longer than the watchdog time, a robot fault,
//   a tracking error above the limit, measured joints failing the pose check.
// - Look-ahead: a governor step is taken only if the poses of braking to a standstill from
//   it (at the acceleration limit, tick by tick) all pass the pose check; else the governor
//   brakes along the path checked at the step before, and holds (status reason "holding: …")
//   until the target changes or the way clears. So a path between two safe targets that
//   grazes is never commanded, and the session stays armed. Exact for one channel; several
//   channels (EGM's arms) are paired tick by tick. A commanded pose that still fails the check
//   is not sent: it stops at the last good pose at once and disarms.
// - Real time: a channel's governor advances one step of `period` per controller tick that its
//   replies land on (MotionPacer), whatever the arrival pattern of the feedback; other replies
//   repeat the command.
// - Hard limits: while a channel's measured joints are outside the robot's joint limits it gets
//   no command at all (none may lie outside them, and jumping inside is no option), it is
//   disarmed and arming is refused; once measured inside again it restarts from there. From
//   the margin (inside the limits, outside the band) commands only move inwards: targets are
//   clamped into the band.
// Not thread-safe: the links call it under their own mutex. Times are seconds on one clock.
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <shapectl/link/motion_governor.hpp>
#include <shapectl/link/motion_pacing.hpp>
#include <shapectl/link/robot_link.hpp>

namespace shapectl {

class SessionLog;

struct LinkChannel {
  std::string name;         // "robot", "left", "right"
  std::vector<int> joints;  // indices into θ, in the order the channel carries them
};

struct SupervisorSettings {
  double watchdog_timeout = 0.1;    // s without feedback on a channel: hold and disarm
  double max_tracking_error = 0.2;  // rad between commanded and measured while armed
  double arrive_tolerance = 1e-3;   // rad: measured this close to the commanded target
  double period = 0.004;            // s, the controller cycle: one governor step's time
};

// What to do with one feedback sample.
struct FeedbackStep {
  bool send = false;       // reply with command(); false: send nothing
  bool advanced = false;   // the governor took a step (else the command is the previous one)
  bool from_rest = false;  // ... after zeroing its velocity (the pose was held over a gap)
  double send_at = 0;      // when the reply should leave (s, `now`'s clock): now or a little later
};

// Full-θ check of a pose (e.g. self-collision): true when fine, else false and `why` set.
using PoseCheck = std::function<bool(const Eigen::VectorXd& joints, std::string* why)>;

class LinkSupervisor {
 public:
  // `hard_lower`/`hard_upper`: the robot's joint limits (targets outside are unsafe);
  // `limits`: the governor's band and rates, full θ. `check` may be empty; `log` may be null.
  LinkSupervisor(std::string kind, std::vector<std::string> joint_names,
                 std::vector<LinkChannel> channels, Eigen::VectorXd hard_lower,
                 Eigen::VectorXd hard_upper, GovernorLimits limits, SupervisorSettings settings,
                 PoseCheck check = {}, SessionLog* log = nullptr);

  const std::vector<LinkChannel>& channels() const { return channels_; }
  const GovernorLimits& limits() const { return limits_; }

  // Why the optimizer's θ (full, active-joint order) must not be commanded; empty when it may.
  // Const and free of shared state (the pose check may be slow): call it outside any lock.
  std::string target_problem(const Eigen::VectorXd& joints, bool safe) const;
  // Takes θ as the target when `problem` (from target_problem) is empty, else refuses it and
  // disarms. Returns whether it was taken.
  bool set_target(const Eigen::VectorXd& joints, const std::string& problem);
  bool arm(double now, std::string* why_not);
  void disarm(const std::string& reason);

  // One feedback sample of `channel` (its joints, rad, channel order), stamped
  // `controller_time` by the controller (s, its clock), arrived at `now`; `fault` is non-empty
  // when the robot says it cannot follow. Advances that channel's governor by at most one step
  // for the controller tick the reply lands on; command() is then the command to send at
  // the returned send_at.
  FeedbackStep on_feedback(int channel, const Eigen::VectorXd& measured, std::string_view fault,
                           double now, double controller_time);
  bool connected(int channel) const { return state_[static_cast<std::size_t>(channel)].connected; }
  const Eigen::VectorXd& command(int channel) const;
  const Eigen::VectorXd& command_velocity(int channel) const;

  // Marks channels whose feedback is older than the watchdog time as disconnected and
  // disarms if armed. Call regularly (every sample period or so), also without feedback.
  void check_watchdog(double now);

  LinkStatus status(double now) const;

 private:
  struct Channel {
    LinkChannel spec;
    MotionGovernor governor;
    MotionPacer pacer;
    Eigen::VectorXd measured;
    double last_feedback = -std::numeric_limits<double>::infinity();
    bool connected = false;
    std::string fault;
    std::string outside;   // why the measured joints are outside the hard limits; empty: inside
    std::string holding;   // while armed: why it holds short of the target; empty: it moves
    bool blocked = false;  // holding at a standstill: the first step from it leaves no safe stop
  };
  std::string outside_limits(const Channel& c, const Eigen::VectorXd& measured) const;
  void log(std::string_view event, const nlohmann::json& fields) const;
  Eigen::VectorXd channel_part(const Eigen::VectorXd& full, const Channel& c) const;
  Eigen::VectorXd full_commanded() const;
  // One step of `channel`'s governor towards the target if every pose on the way to a
  // standstill from there is clear, else one step of braking (whose path was checked before).
  void step_clear_of_collisions(int channel, double now);
  // Whether the poses while every channel brakes to a standstill, tick by tick, `channel`
  // from `next` and the others from where they are, all pass the pose check; else `why`.
  bool stop_is_clear(int channel, const MotionGovernor& next, std::string* why) const;
  // Why the measured joints of all channels fail the pose check; empty when they pass.
  std::string measured_problem() const;

  std::string kind_;
  std::vector<std::string> joint_names_;
  std::vector<LinkChannel> channels_;
  std::vector<Channel> state_;
  Eigen::VectorXd hard_lower_, hard_upper_;
  GovernorLimits limits_;
  SupervisorSettings settings_;
  PoseCheck check_;
  SessionLog* log_;

  bool armed_ = false;
  std::string reason_ = "not armed";
  bool has_target_ = false;
  std::string target_problem_;  // why the last target was refused; empty when it was fine
  Eigen::VectorXd target_;      // band-clamped
  double last_hold_logged_ = -std::numeric_limits<double>::infinity();
};

}  // namespace shapectl
