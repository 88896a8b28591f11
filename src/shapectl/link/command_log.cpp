#include <shapectl/link/command_log.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>

namespace shapectl {

namespace {

// Rounding slack: positions are sums of v·dt, compared as differences.
constexpr double slack = 1e-9;
constexpr std::size_t max_logged_joints = 1000;

// A logged vector of exactly `n` entries. JSON has no infinity or NaN: they were written as
// null, read back as `null_value` (none: a null is refused).
Eigen::VectorXd logged_vector(const JsonInput& j, int n, std::optional<double> null_value) {
  const std::string expected =
      "an array of " + std::to_string(n) + " numbers" + (null_value ? " or nulls" : "");
  if (!j.is_array() || j.size() != static_cast<std::size_t>(n)) j.fail(expected);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) {
    const nlohmann::json& x = j.raw()[static_cast<std::size_t>(i)];
    // The common case without building a JsonInput (a path string) per element.
    if (x.is_number() && std::isfinite(x.get<double>())) v[i] = x.get<double>();
    else
      v[i] = null_value && x.is_null() ? *null_value : j.at(static_cast<std::size_t>(i)).number();
  }
  return v;
}

int joint_names_count(const JsonInput& names) {
  const std::size_t n = names.size();
  if (n == 0 || n > max_logged_joints) names.fail("1 to 1000 joint names");
  for (std::size_t i = 0; i < n; ++i) names.at(i).string();
  return static_cast<int>(n);
}

struct LinkEvent {
  GovernorLimits limits;
  std::vector<LinkChannel> channels;
  double period = 0;
};

// A "link" event with every field checked against its own joint count.
LinkEvent read_link_event(const JsonInput& f) {
  const int n = joint_names_count(f.at("joint_names"));
  constexpr double inf = std::numeric_limits<double>::infinity();
  LinkEvent link{{logged_vector(f.at("lower"), n, -inf), logged_vector(f.at("upper"), n, inf),
                  logged_vector(f.at("velocity"), n, inf),
                  logged_vector(f.at("acceleration"), n, inf)},
                 {},
                 f.at("period").positive()};
  for (int i = 0; i < n; ++i) {
    if (!(link.limits.lower[i] <= link.limits.upper[i]))
      f.at("upper")
          .at(static_cast<std::size_t>(i))
          .fail("a number >= lower (" + std::to_string(link.limits.lower[i]) + ")");
    if (!(link.limits.velocity[i] > 0))
      f.at("velocity").at(static_cast<std::size_t>(i)).fail("a positive number or null");
    if (!(link.limits.acceleration[i] > 0))
      f.at("acceleration").at(static_cast<std::size_t>(i)).fail("a positive number or null");
  }
  const JsonInput channels = f.at("channels");
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const JsonInput joints = channels.at(c).at("joints");
    LinkChannel channel{channels.at(c).at("name").string(), {}};
    for (std::size_t k = 0; k < joints.size(); ++k)
      channel.joints.push_back(static_cast<int>(joints.at(k).integer_in(0, n - 1)));
    link.channels.push_back(std::move(channel));
  }
  return link;
}

}  // namespace

void log_link_started(SessionLog& log, const std::string& kind,
                      const std::vector<std::string>& joint_names,
                      const std::vector<LinkChannel>& channels, const GovernorLimits& limits,
                      double period) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : channels) list.push_back({{"name", c.name}, {"joints", c.joints}});
  log.write_header("link", {{"kind", kind},
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
  int joint_count = -1;  // named by the last "session" or "link" event
  auto violation = [&](const LoggedEvent& e, const std::string& what) {
    if (check.violations.size() < 20)
      check.violations.push_back(source + ":" + std::to_string(e.line) + ": " + what);
    else if (check.violations.size() == 20)
      check.violations.push_back("(more violations not listed)");
  };
  for (const auto& e : events) {
    const JsonInput f(e.fields, source + ":" + std::to_string(e.line));
    if (e.event == "session" || e.event == "scene") {
      const std::string scene = f.has("scene") ? f.at("scene").string() : "";
      if (e.event == "session" && !scene.empty()) check.scene = scene;
      if (f.has("joint_names")) joint_count = joint_names_count(f.at("joint_names"));
    } else if (e.event == "link") {
      ++check.links;
      const LinkEvent link = read_link_event(f);
      joint_count = link.limits.size();
      channels.clear();
      for (const auto& c : link.channels) channels[c.name] = {link.limits.subset(c.joints), {}};
      dt = link.period;
    } else if (e.event == "optimizer") {
      if (joint_count < 0)
        throw InputError(f.source(), "joints",
                         "expected a \"session\" or \"link\" event naming the joints before "
                         "this optimizer result");
      const Eigen::VectorXd joints = logged_vector(f.at("joints"), joint_count, std::nullopt);
      const bool safe = f.has("safe") && f.at("safe").boolean();
      check.optimizer_results.push_back({e.line, e.t, joints, safe});
    } else if (e.event == "connect") {
      const auto it = channels.find(f.at("channel").string());
      if (it != channels.end()) it->second.last.clear();
    } else if (e.event == "command") {
      const auto name = f.at("channel").string();
      const auto it = channels.find(name);
      if (it == channels.end()) {
        violation(e, "command for channel '" + name + "' without a link event naming it");
        continue;
      }
      Channel& c = it->second;
      f.at("seq").integer_in(0, 9'000'000'000'000'000);
      // A null (a non-finite number written) is a violation below, not a malformed log.
      const Eigen::VectorXd q = logged_vector(f.at("joints"), c.limits.size(), NAN);
      logged_vector(f.at("measured"), c.limits.size(), NAN);
      const bool hold = f.has("hold") && f.at("hold").boolean();
      const bool from_rest = f.has("from_rest") && f.at("from_rest").boolean();
      ++check.commands;
      if (!q.allFinite()) {
        violation(e,
                  name + ": command is not " + std::to_string(c.limits.size()) + " finite values");
        continue;
      }
      if (hold && !c.last.empty() && q != c.last.back()) violation(e, name + ": a hold that moved");
      // Restarted from rest: the step before counts as zero.
      if (!c.last.empty() && from_rest) c.last = {c.last.back(), c.last.back()};
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
