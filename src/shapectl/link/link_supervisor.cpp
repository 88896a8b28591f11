#include <shapectl/link/link_supervisor.hpp>

#include <cassert>
#include <cmath>
#include <sstream>

#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/session_log.hpp>

namespace shapectl {

namespace {

std::string format(double value, int precision = 3) {
  std::ostringstream s;
  s.precision(precision);
  s << value;
  return s.str();
}

}  // namespace

LinkSupervisor::LinkSupervisor(std::string kind, std::vector<std::string> joint_names,
                               std::vector<LinkChannel> channels, Eigen::VectorXd hard_lower,
                               Eigen::VectorXd hard_upper, GovernorLimits limits,
                               SupervisorSettings settings, PoseCheck check, SessionLog* log)
    : kind_(std::move(kind)),
      joint_names_(std::move(joint_names)),
      channels_(std::move(channels)),
      hard_lower_(std::move(hard_lower)),
      hard_upper_(std::move(hard_upper)),
      limits_(std::move(limits)),
      settings_(settings),
      check_(std::move(check)),
      log_(log) {
  assert(static_cast<int>(joint_names_.size()) == limits_.size());
  for (const auto& spec : channels_) {
    Channel c{spec,
              MotionGovernor(limits_.subset(spec.joints)),
              MotionPacer(settings_.period),
              {},
              -std::numeric_limits<double>::infinity(),
              false,
              {},
              {},
              {},
              false};
    c.measured = c.governor.position();
    state_.push_back(std::move(c));
  }
  target_ = Eigen::VectorXd::Zero(limits_.size());
}

void LinkSupervisor::log(std::string_view event, const nlohmann::json& fields) const {
  if (log_) log_->write(event, fields);
}

Eigen::VectorXd LinkSupervisor::channel_part(const Eigen::VectorXd& full, const Channel& c) const {
  Eigen::VectorXd part(static_cast<Eigen::Index>(c.spec.joints.size()));
  for (std::size_t i = 0; i < c.spec.joints.size(); ++i)
    part[static_cast<Eigen::Index>(i)] = full[c.spec.joints[i]];
  return part;
}

Eigen::VectorXd LinkSupervisor::full_commanded() const {
  Eigen::VectorXd full = target_;  // joints on no channel (none in practice) show the target
  for (const auto& c : state_)
    for (std::size_t i = 0; i < c.spec.joints.size(); ++i)
      full[c.spec.joints[i]] = c.governor.position()[static_cast<Eigen::Index>(i)];
  return full;
}

std::string LinkSupervisor::target_problem(const Eigen::VectorXd& joints, bool safe) const {
  if (joints.size() != limits_.size())
    return "target has " + std::to_string(joints.size()) + " joints, expected " +
           std::to_string(limits_.size());
  for (Eigen::Index i = 0; i < joints.size(); ++i)
    if (!std::isfinite(joints[i]))
      return "target for " + joint_names_[static_cast<std::size_t>(i)] + " is not finite";
  if (!safe) return "optimizer marked the target unsafe (collision or limits)";
  for (Eigen::Index i = 0; i < joints.size(); ++i)
    if (joints[i] < hard_lower_[i] || joints[i] > hard_upper_[i])
      return "target for " + joint_names_[static_cast<std::size_t>(i)] + " (" + format(joints[i]) +
             " rad) is outside its limits [" + format(hard_lower_[i]) + ", " +
             format(hard_upper_[i]) + "]";
  std::string why;
  if (check_ && !check_(joints, &why)) return "target pose: " + why;
  return {};
}

bool LinkSupervisor::set_target(const Eigen::VectorXd& joints, const std::string& why) {
  if (!why.empty()) {
    if (target_problem_.empty() || armed_) log("target_rejected", {{"reason", why}});
    target_problem_ = why;
    if (armed_) disarm(why);
    else reason_ = why;
    return false;
  }
  if (!target_problem_.empty() && !armed_) reason_ = "not armed";
  assert(joints.size() == limits_.size());
  target_problem_.clear();
  const Eigen::VectorXd target = joints.cwiseMax(limits_.lower).cwiseMin(limits_.upper);
  if (target != target_)
    for (auto& c : state_) c.blocked = false;
  has_target_ = true;
  target_ = target;
  return true;
}

bool LinkSupervisor::arm(double now, std::string* why_not) {
  check_watchdog(now);
  std::string why;
  for (const auto& c : state_) {
    if (!c.connected) why = c.spec.name + ": no feedback";
    else if (!c.outside.empty()) why = c.spec.name + ": " + c.outside;
    else if (!c.fault.empty()) why = c.spec.name + ": " + c.fault;
    if (!why.empty()) break;
  }
  if (why.empty() && !target_problem_.empty()) why = target_problem_;
  if (why.empty()) why = measured_problem();
  if (!why.empty()) {
    if (why_not) *why_not = why;
    log("arm_refused", {{"reason", why}});
    return false;
  }
  if (armed_) return true;
  // Start from where the robot is, unless still braking (then stay continuous).
  for (auto& c : state_)
    if (c.governor.at_rest()) c.governor.reset(c.measured);
  armed_ = true;
  reason_.clear();
  for (auto& c : state_) c.holding.clear(), c.blocked = false;
  log("arm", {{"commanded", vector_json(full_commanded())}});
  return true;
}

void LinkSupervisor::disarm(const std::string& reason) {
  reason_ = reason.empty() ? "disarmed" : reason;
  if (!armed_) return;
  armed_ = false;
  log("disarm", {{"reason", reason_}});
}

std::string LinkSupervisor::outside_limits(const Channel& c,
                                           const Eigen::VectorXd& measured) const {
  for (std::size_t i = 0; i < c.spec.joints.size(); ++i) {
    const int j = c.spec.joints[i];
    const double q = measured[static_cast<Eigen::Index>(i)];
    if (q < hard_lower_[j] || q > hard_upper_[j])
      return joint_names_[static_cast<std::size_t>(j)] + " measured at " + format(q) +
             " rad, outside its limits [" + format(hard_lower_[j]) + ", " + format(hard_upper_[j]) +
             "]: move it inside by hand first";
  }
  return {};
}

FeedbackStep LinkSupervisor::on_feedback(int channel, const Eigen::VectorXd& measured,
                                         std::string_view fault, double now,
                                         double controller_time) {
  Channel& c = state_[static_cast<std::size_t>(channel)];
  assert(measured.size() == c.governor.limits().size() && measured.allFinite());
  const bool resumed = !c.connected || !c.outside.empty();
  c.connected = true;
  c.last_feedback = now;
  c.measured = measured;
  c.fault = fault;
  if (std::string why = outside_limits(c, measured); !why.empty()) {
    if (c.outside != why) log("outside_limits", {{"channel", c.spec.name}, {"reason", why}});
    c.outside = std::move(why);
    if (armed_) disarm(c.spec.name + ": " + c.outside);
    return {};
  }
  c.outside.clear();
  if (resumed) {
    // No jump on (re)connect: command the robot where it is.
    c.governor.reset(measured);
    c.pacer.restart();
    log("connect", {{"channel", c.spec.name}, {"measured", vector_json(measured)}});
  }
  if (armed_ && !c.fault.empty()) disarm(c.spec.name + ": " + c.fault);
  if (armed_) {
    const double error = (measured - c.governor.position()).cwiseAbs().maxCoeff();
    if (error > settings_.max_tracking_error)
      disarm(c.spec.name + ": tracking error " + format(error) + " rad above " +
             format(settings_.max_tracking_error) + " rad");
  }
  // A measured pose is not judged while armed: commands graze at ~0 clearance (the optimizer's
  // poses may), and a robot following them lags a few µm off their path, which the sphere model
  // would call an overlap (a 10-minute drag soak was disarmed so after 79 s). Arming is refused
  // from a colliding measured pose (arm()); commanded poses are checked before they are sent.
  const PaceStep pace = c.pacer.on_feedback(now, controller_time);
  FeedbackStep step{.send = true,
                    .advanced = pace.advance,
                    .from_rest = false,
                    .send_at = pace.send_at};
  if (!pace.advance) return step;
  if (pace.from_rest && !c.governor.at_rest()) {
    c.governor.halt();
    step.from_rest = true;
  }
  const Eigen::VectorXd before = c.governor.position();
  if (armed_ && has_target_) step_clear_of_collisions(channel, now);
  else c.governor.step_stop(settings_.period);
  // Backstop: with several channels the look-ahead pairs their ticks; should it miss, no
  // colliding pose is sent (the stop at once is then the lesser evil).
  std::string why;
  if (check_ && c.governor.position() != before && !check_(full_commanded(), &why)) {
    c.governor.reset(before);
    disarm(c.spec.name + ": commanded pose: " + why);
  }
  return step;
}

void LinkSupervisor::step_clear_of_collisions(int channel, double now) {
  Channel& c = state_[static_cast<std::size_t>(channel)];
  const double dt = settings_.period;
  MotionGovernor next = c.governor;
  next.step_towards(channel_part(target_, c), dt);
  MotionGovernor braking = c.governor;
  braking.step_stop(dt);
  // Braking is always clear: its path was checked before the last step was taken.
  const bool is_braking =
      next.position() == braking.position() && next.velocity() == braking.velocity();
  std::string why;
  if (!check_ || is_braking || stop_is_clear(channel, next, &why)) {
    c.governor = std::move(next);
    c.holding.clear();
    c.blocked = false;
    return;
  }
  // From a standstill the same target always gives the same first step: stuck until it changes.
  c.blocked = c.governor.at_rest();
  c.governor = std::move(braking);
  // Creeping up to the obstacle alternates steps and holds: a log line a second is enough.
  if (now - last_hold_logged_ >= 1) {
    log("hold", {{"channel", c.spec.name}, {"reason", why}});
    last_hold_logged_ = now;
  }
  c.holding =
      c.spec.name + ": holding: going on towards the target leaves no safe stop (" + why + ")";
}

bool LinkSupervisor::stop_is_clear(int channel, const MotionGovernor& next,
                                   std::string* why) const {
  std::vector<MotionGovernor> governors;
  for (std::size_t i = 0; i < state_.size(); ++i)
    governors.push_back(static_cast<int>(i) == channel ? next : state_[i].governor);
  Eigen::VectorXd full = target_;
  for (;;) {
    bool at_rest = true;
    for (std::size_t i = 0; i < governors.size(); ++i) {
      const auto& joints = state_[i].spec.joints;
      for (std::size_t k = 0; k < joints.size(); ++k)
        full[joints[k]] = governors[i].position()[static_cast<Eigen::Index>(k)];
      at_rest = at_rest && governors[i].at_rest();
    }
    if (!check_(full, why)) return false;
    if (at_rest) return true;
    for (auto& g : governors) g.step_stop(settings_.period);
  }
}

std::string LinkSupervisor::measured_problem() const {
  if (!check_) return {};
  Eigen::VectorXd full = target_;
  for (const auto& c : state_)
    for (std::size_t i = 0; i < c.spec.joints.size(); ++i)
      full[c.spec.joints[i]] = c.measured[static_cast<Eigen::Index>(i)];
  std::string why;
  return check_(full, &why) ? std::string() : "measured pose: " + why;
}

const Eigen::VectorXd& LinkSupervisor::command(int channel) const {
  return state_[static_cast<std::size_t>(channel)].governor.position();
}

const Eigen::VectorXd& LinkSupervisor::command_velocity(int channel) const {
  return state_[static_cast<std::size_t>(channel)].governor.velocity();
}

void LinkSupervisor::check_watchdog(double now) {
  for (auto& c : state_) {
    if (!c.connected || now - c.last_feedback <= settings_.watchdog_timeout) continue;
    c.connected = false;
    const std::string why = c.spec.name + ": no feedback for " + format(now - c.last_feedback) +
                            " s (watchdog " + format(settings_.watchdog_timeout) + " s)";
    log("feedback_lost", {{"channel", c.spec.name}, {"reason", why}});
    if (armed_) disarm(why);
  }
}

LinkStatus LinkSupervisor::status(double now) const {
  LinkStatus s;
  s.kind = kind_;
  s.armed = armed_;
  s.reason = reason_;
  s.connected = !state_.empty();
  s.measured = Eigen::VectorXd::Zero(limits_.size());
  double oldest = 0;
  bool arrived = armed_ && has_target_;
  for (const auto& c : state_) {
    if (armed_ && !c.holding.empty()) s.reason = c.holding;
    s.blocked = s.blocked || (armed_ && c.blocked);
    s.connected = s.connected && c.connected;
    oldest = std::max(oldest, now - c.last_feedback);
    for (std::size_t i = 0; i < c.spec.joints.size(); ++i)
      s.measured[c.spec.joints[i]] = c.measured[static_cast<Eigen::Index>(i)];
    arrived =
        arrived && c.governor.arrived_at(channel_part(target_, c)) &&
        (c.measured - c.governor.position()).cwiseAbs().maxCoeff() <= settings_.arrive_tolerance;
  }
  s.feedback_age = oldest;
  s.commanded = full_commanded();
  s.arrived = arrived;
  return s;
}

}  // namespace shapectl
