#include <shapectl/link/command_log.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <shapectl/io/json_eigen.hpp>

namespace shapectl {

namespace {

// Rounding slack: positions are sums of v·dt, compared as differences.
constexpr double slack = 1e-9;

}  // namespace

void log_link_started(SessionLog& log, const std::string& kind,
                      const std::vector<std::string>& joint_names,
                      const std::vector<LinkChannel>& channels, const GovernorLimits& limits,
                      double period) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : channels) list.push_back({{"name", c.name}, {"joints", c.joints}});
  log.write("link", {{"kind", kind},
                     {"joint_names", joint_names},
                     {"channels", list},
                     {"period", period},
                     {"lower", vector_json(limits.lower)},
                     {"upper", vector_json(limits.upper)},
                     {"velocity", vector_json(limits.velocity)},
                     {"acceleration", vector_json(limits.acceleration)}});
}

void log_command(SessionLog& log, const std::string& channel, std::uint64_t seq,
                 const Eigen::VectorXd& joints, const Eigen::VectorXd& measured,
                 const FeedbackStep& step) {
  nlohmann::json fields = {{"channel", channel},
                           {"seq", seq},
                           {"joints", vector_json(joints)},
                           {"measured", vector_json(measured)}};
  if (!step.advanced) fields["hold"] = true;
  if (step.from_rest) fields["from_rest"] = true;
  log.write("command", fields);
}

CommandLogCheck check_command_log(const std::vector<LoggedEvent>& events,
                                  const std::string& source) {
  struct Channel {
    GovernorLimits limits;
    std::vector<Eigen::VectorXd> last;  // up to two previous commands
  };
  CommandLogCheck check;
  std::map<std::string, Channel> channels;
  double dt = 0;
  auto violation = [&](const LoggedEvent& e, const std::string& what) {
    if (check.violations.size() < 20)
      check.violations.push_back(source + ":" + std::to_string(e.line) + ": " + what);
    else if (check.violations.size() == 20)
      check.violations.push_back("(more violations not listed)");
  };
  for (const auto& e : events) {
    const auto& f = e.fields;
    if (e.event == "link") {
      ++check.links;
      // JSON has no infinity: unbounded limits were written as null.
      constexpr double inf = std::numeric_limits<double>::infinity();
      GovernorLimits all{vector_from_json(f.at("lower"), -inf),
                         vector_from_json(f.at("upper"), inf),
                         vector_from_json(f.at("velocity"), inf),
                         vector_from_json(f.at("acceleration"), inf)};
      channels.clear();
      for (const auto& c : f.at("channels"))
        channels[c.at("name").get<std::string>()] = {all.subset(
                                                         c.at("joints").get<std::vector<int>>()),
                                                     {}};
      dt = f.at("period").get<double>();
    } else if (e.event == "connect") {
      const auto it = channels.find(f.at("channel").get<std::string>());
      if (it != channels.end()) it->second.last.clear();
    } else if (e.event == "command") {
      const auto name = f.at("channel").get<std::string>();
      const auto it = channels.find(name);
      if (it == channels.end()) {
        violation(e, "command for channel '" + name + "' without a link event naming it");
        continue;
      }
      Channel& c = it->second;
      const Eigen::VectorXd q = vector_from_json(f.at("joints"), NAN);
      ++check.commands;
      if (q.size() != c.limits.size() || !q.allFinite()) {
        violation(e,
                  name + ": command is not " + std::to_string(c.limits.size()) + " finite values");
        continue;
      }
      const bool hold = f.value("hold", false);
      if (hold && !c.last.empty() && q != c.last.back()) violation(e, name + ": a hold that moved");
      // Restarted from rest: the step before counts as zero.
      if (!c.last.empty() && f.value("from_rest", false)) c.last = {c.last.back(), c.last.back()};
      for (Eigen::Index i = 0; i < q.size() && !hold; ++i) {
        const std::string joint = name + " joint " + std::to_string(i);
        // Outside the band (started in the margin) only ever inwards.
        auto out = [&](double x) {
          return std::max({0.0, c.limits.lower[i] - x, x - c.limits.upper[i]});
        };
        if (out(q[i]) > slack && !c.last.empty() && out(q[i]) > out(c.last.back()[i]) + slack)
          violation(e,
                    joint + ": " + std::to_string(q[i]) + " rad outside the band, moving outwards");
        if (c.last.empty()) continue;
        const double dq = std::abs(q[i] - c.last.back()[i]);
        const double v_ratio = dq / (c.limits.velocity[i] * dt);
        check.velocity_ratio = std::max(check.velocity_ratio, v_ratio);
        if (dq > c.limits.velocity[i] * dt + slack)
          violation(e, joint + ": step " + std::to_string(dq) + " rad above v·dt");
        if (c.last.size() < 2) continue;
        const double ddq = std::abs(q[i] - 2 * c.last.back()[i] + c.last.front()[i]);
        check.acceleration_ratio =
            std::max(check.acceleration_ratio, ddq / (c.limits.acceleration[i] * dt * dt));
        if (ddq > c.limits.acceleration[i] * dt * dt + slack)
          violation(e, joint + ": second difference " + std::to_string(ddq) + " rad above a·dt²");
      }
      if (hold) continue;
      if (c.last.size() == 2) c.last.erase(c.last.begin());
      c.last.push_back(q);
    }
  }
  return check;
}

}  // namespace shapectl
