#pragma once
// What links write to a SessionLog, and the check of a whole log against the limits it states.
//
//   {"event":"link","kind":"egm","joint_names":[..],"channels":[{"name":"left","joints":[..]}],
//    "period":0.004,"lower":[..],"upper":[..],"velocity":[..],"acceleration":[..]}
//   {"event":"command","channel":"left","seq":17,"joints":[..],"measured":[..]}   (rad)
//   (+ "hold":true when the command repeats the previous one because real time did not allow
//    a step, "from_rest":true when the governor restarted from rest after the pose was held)
//   {"event":"connect"|"feedback_lost"|"arm"|"disarm"|"arm_refused"|"target_rejected", ..}
#include <string>
#include <vector>

#include <Eigen/Core>

#include <shapectl/io/session_log.hpp>
#include <shapectl/link/link_supervisor.hpp>

namespace shapectl {

void log_link_started(SessionLog& log, const std::string& kind,
                      const std::vector<std::string>& joint_names,
                      const std::vector<LinkChannel>& channels, const GovernorLimits& limits,
                      double period);
void log_command(SessionLog& log, const std::string& channel, std::uint64_t seq,
                 const Eigen::VectorXd& joints, const Eigen::VectorXd& measured,
                 const FeedbackStep& step = {.send = true, .advanced = true});

// An optimizer result the log holds ("optimizer" events of `serve`), for replaying it.
struct LoggedOptimizerResult {
  int line = 0;
  double t = 0;            // s
  Eigen::VectorXd joints;  // rad, the log's joint count
  bool safe = false;
};

struct CommandLogCheck {
  int links = 0;     // "link" events (a log may hold several sessions)
  int commands = 0;  // "command" events checked
  // Largest |Δq|/(v·dt) and |Δ²q|/(a·dt²) seen: ≤ 1 means within the limits.
  double velocity_ratio = 0;
  double acceleration_ratio = 0;
  std::vector<std::string> violations;  // "log.jsonl:120: left joint 3: ..." (first 20)
  std::string scene;                    // of the last "session" event naming one, or empty
  std::vector<LoggedOptimizerResult> optimizer_results;
  bool ok() const { return violations.empty(); }
};

// Checks every command of every channel: velocity and acceleration within the limits of the
// "link" event before it, per controller cycle (consecutive advancing commands are one
// governor step of dt apart; a "hold" is skipped; "from_rest" means the
// previous step counts as zero), and position inside the band unless holding still. A
// "connect" event restarts that channel's sequence (the governor is reset to the measured
// position then). Every field it reads is checked first, its size against the joint count the
// log names ("joint_names" of the "link" event before, for optimizer results also of a
// "session" or "scene" event): a malformed field is an InputError "<source>:<line>: <field>:
// expected ...".
CommandLogCheck check_command_log(const std::vector<LoggedEvent>& events,
                                  const std::string& source);

}  // namespace shapectl
