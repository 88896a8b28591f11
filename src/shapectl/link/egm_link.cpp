#include <shapectl/link/egm_link.hpp>

#include <arpa/inet.h>
#include <poll.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <regex>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

namespace {

constexpr std::size_t latency_capacity = 65536;
constexpr int max_logged_rejections = 20;
// ABB axis numbers in chain order.
constexpr std::array<int, 7> chain_axes = {1, 2, 7, 3, 4, 5, 6};

Eigen::VectorXd to_vector(const ArmJoints& q) { return q; }

std::uint64_t sender_key(const sockaddr_in& a) {
  return std::uint64_t{ntohl(a.sin_addr.s_addr)} << 16 | ntohs(a.sin_port);
}

std::string address_text(const sockaddr_in& a) {
  char host[INET_ADDRSTRLEN] = "?";
  ::inet_ntop(AF_INET, &a.sin_addr, host, sizeof host);
  return std::string(host) + ":" + std::to_string(ntohs(a.sin_port));
}

}  // namespace

std::vector<LinkChannel> egm_arm_channels(const RobotModel& robot) {
  const std::string where = robot.source() + ": robot '" + robot.name() + "'";
  const std::regex pattern("yumi_joint_([1-7])_([lr])");
  std::array<std::array<int, 7>, 2> index;  // [arm][chain position] → θ index, -1 when absent
  for (auto& arm : index) arm.fill(-1);
  const auto names = robot.active_joint_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::smatch m;
    if (!std::regex_match(names[i], m, pattern))
      throw InputError(where, "active joint '" + names[i] + "'",
                       "egm streams YuMi arms only: expected yumi_joint_<1..7>_<l|r>");
    const int arm = m[2] == "l" ? 0 : 1;
    const int axis = std::stoi(m[1]);
    const auto pos = std::find(chain_axes.begin(), chain_axes.end(), axis) - chain_axes.begin();
    index[arm][static_cast<std::size_t>(pos)] = static_cast<int>(i);
  }
  std::vector<LinkChannel> channels;
  const char* arm_names[2] = {"left", "right"};
  const char* suffix[2] = {"l", "r"};
  for (int arm = 0; arm < 2; ++arm) {
    const auto& ix = index[static_cast<std::size_t>(arm)];
    const auto present = std::count_if(ix.begin(), ix.end(), [](int i) { return i >= 0; });
    if (present == 0) continue;
    if (present < 7) {
      std::string missing;
      for (std::size_t p = 0; p < 7; ++p)
        if (ix[p] < 0)
          missing += (missing.empty() ? "" : ", ") + std::string("yumi_joint_") +
                     std::to_string(chain_axes[p]) + "_" + suffix[arm];
      throw InputError(where, std::string(arm_names[arm]) + " arm",
                       "egm commands whole arms: all 7 joints must be active; missing " + missing);
    }
    channels.push_back({arm_names[arm], std::vector<int>(ix.begin(), ix.end())});
  }
  if (channels.empty()) throw InputError(where, "", "egm needs active YuMi arm joints; none are");
  return channels;
}

EgmLink::EgmLink(const LinkConfig& config, const RobotModel& robot, PoseCheck check,
                 std::shared_ptr<SessionLog> log)
    : SupervisedLink(config.egm_period, log,
                     LinkSupervisor(to_string(LinkKind::Egm), robot.active_joint_names(),
                                    egm_arm_channels(robot), robot.lower_limits(),
                                    robot.upper_limits(), governor_limits(config, robot),
                                    {config.watchdog_timeout, config.max_tracking_error,
                                     config.arrive_tolerance, config.egm_period},
                                    std::move(check), log.get())),
      buffer_(EgmCodec::max_datagram + 1) {
  for (const auto& c : supervisor_.channels()) {
    const int port = c.name == "left" ? config.egm_left_port : config.egm_right_port;
    sockets_.emplace_back(config.egm_address, port, "egm " + c.name + " port");
  }
  next_seqno_.assign(sockets_.size(), 1);
  filters_.resize(sockets_.size());
  pending_.resize(sockets_.size());
  latency_us_.reserve(latency_capacity);
  if (log_)
    log_link_started(*log_, to_string(LinkKind::Egm), robot.active_joint_names(),
                     supervisor_.channels(), supervisor_.limits(), period_);
}

EgmLink::~EgmLink() { stop(); }

void EgmLink::run(std::stop_token stop) {
  std::vector<pollfd> fds;
  for (const auto& s : sockets_) fds.push_back({s.fd(), POLLIN, 0});
  // Wake at least every millisecond for the watchdog and for stop requests, and when a
  // held-back reply is due.
  constexpr double poll_interval = 1e-3;
  while (!stop.stop_requested()) {
    double wait = poll_interval;
    for (const auto& queue : pending_)
      if (!queue.empty()) wait = std::min(wait, std::max(queue.front().due - now(), 0.0));
    const timespec timeout{0, static_cast<long>(wait * 1e9)};
    ::ppoll(fds.data(), fds.size(), &timeout, nullptr);
    for (std::size_t c = 0; c < sockets_.size(); ++c) {
      if (!(fds[c].revents & POLLIN)) continue;
      sockaddr_in from{};
      long n;
      while ((n = sockets_[c].receive(buffer_, &from)) >= 0)
        handle_datagram(static_cast<int>(c),
                        std::string_view(buffer_.data(),
                                         static_cast<std::size_t>(
                                             std::min<long>(n, static_cast<long>(buffer_.size())))),
                        from, std::chrono::steady_clock::now());
    }
    send_due_replies();
    std::lock_guard lock(mutex_);
    supervisor_.check_watchdog(now());
  }
}

void EgmLink::handle_datagram(int channel, std::string_view datagram, const sockaddr_in& from,
                              std::chrono::steady_clock::time_point arrived) {
  const auto c = static_cast<std::size_t>(channel);
  EgmFeedback feedback;
  std::string_view why;
  // A datagram that filled the whole buffer was at least one byte too long: the codec sees
  // it as oversized.
  if (!codec_.decode_robot(datagram, feedback, &why)) {
    std::uint64_t count;
    {
      std::lock_guard lock(mutex_);
      count = ++rejected_;
    }
    if (log_ && count <= max_logged_rejections)
      log_->write("datagram_rejected", {{"channel", supervisor_.channels()[c].name},
                                        {"bytes", datagram.size()},
                                        {"reason", why}});
    return;
  }
  EgmCommand command;
  Reply reply;
  reply.to = from;
  reply.arrived = arrived;
  reply.measured = to_vector(feedback.joints);
  FeedbackVerdict verdict;
  bool log_foreign = false;
  std::string bound_to;
  {
    std::lock_guard lock(mutex_);
    FeedbackFilter& filter = filters_[c];
    // After a feedback loss the controller may have restarted its counter.
    if (!supervisor_.connected(channel)) filter.forget_sequence();
    const bool first = !filter.bound();
    verdict = filter.accept(sender_key(from), feedback.seqno, feedback.tm);
    if (first) bound_to = address_text(from);
    if (verdict == FeedbackVerdict::foreign && foreign_logged_ < max_logged_rejections) {
      ++foreign_logged_;
      log_foreign = true;
    }
    if (verdict == FeedbackVerdict::accepted) {
      // Steps are paced by the controller's ticks: its cycle must be the one configured.
      std::string fault(feedback.fault());
      const auto period_ms = std::llround(period_ * 1000);
      if (fault.empty() && filter.cycle_ms() != 0 && filter.cycle_ms() != period_ms)
        fault = "the controller's sample period is " + std::to_string(filter.cycle_ms()) +
                " ms (feedback time stamps), egm_period is " + std::to_string(period_ms) +
                " ms: set \\SampleRate or egm_period to match";
      reply.step =
          supervisor_.on_feedback(channel, reply.measured, fault, now(), filter.controller_time());
      command.joints = supervisor_.command(channel);
      command.velocity =
          reply.step.advanced ? supervisor_.command_velocity(channel) : ArmJoints::Zero();
      if (reply.step.send) command.seqno = next_seqno_[c]++;
      command.tm = static_cast<std::uint32_t>(reply.step.send_at * 1000);
    }
  }
  if (log_ && !bound_to.empty())
    log_->write("controller_bound",
                {{"channel", supervisor_.channels()[c].name}, {"address", bound_to}});
  if (log_ && log_foreign)
    log_->write("foreign_sender",
                {{"channel", supervisor_.channels()[c].name},
                 {"address", address_text(from)},
                 {"note", "ignored; at most " + std::to_string(max_logged_rejections) +
                              " such lines are logged"}});
  if (verdict != FeedbackVerdict::accepted || !reply.step.send) return;
  reply.bytes = codec_.encode_sensor(command);
  reply.joints = command.joints;
  reply.seqno = command.seqno;
  reply.due = reply.step.send_at;
  // Replies leave in order; one held back until it surely lands after a tick waits here.
  auto& queue = pending_[c];
  if (queue.empty() && reply.due <= now()) {
    send_reply(channel, reply);
  } else if (queue.size() < max_pending_replies) {
    queue.push_back(std::move(reply));
  }
}

void EgmLink::send_due_replies() {
  for (std::size_t c = 0; c < pending_.size(); ++c)
    while (!pending_[c].empty() && pending_[c].front().due <= now()) {
      send_reply(static_cast<int>(c), pending_[c].front());
      pending_[c].pop_front();
    }
}

void EgmLink::send_reply(int channel, const Reply& reply) {
  const auto c = static_cast<std::size_t>(channel);
  const bool sent = !reply.bytes.empty() && sockets_[c].send_to(reply.bytes, reply.to);
  const auto done = std::chrono::steady_clock::now();
  const float us = std::chrono::duration<float, std::micro>(done - reply.arrived).count();
  {
    std::lock_guard lock(mutex_);
    if (latency_us_.size() < latency_capacity) latency_us_.push_back(us);
    else latency_us_[latency_next_] = us;
    latency_next_ = (latency_next_ + 1) % latency_capacity;
    if (reply.bytes.empty()) supervisor_.disarm("internal: non-finite command not sent");
    if (sent) ++commands_sent_;
  }
  if (log_ && sent)
    log_command(*log_, supervisor_.channels()[c].name, reply.seqno, reply.joints, reply.measured,
                reply.step);
}

LinkStatus EgmLink::status() const {
  std::lock_guard lock(mutex_);
  LinkStatus s = supervisor_.status(now());
  s.commands_sent = commands_sent_;
  s.rejected_datagrams = rejected_;
  for (const auto& f : filters_) {
    s.lost_datagrams += f.counts().lost;
    s.stale_datagrams += f.counts().stale;
    s.foreign_datagrams += f.counts().foreign;
  }
  return s;
}

LatencyStats EgmLink::latency() const {
  std::vector<float> samples;
  {
    std::lock_guard lock(mutex_);
    samples = latency_us_;
  }
  LatencyStats s;
  s.samples = samples.size();
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  auto at = [&](double q) { return samples[static_cast<std::size_t>(q * (samples.size() - 1))]; };
  s.median_us = at(0.5);
  s.p99_us = at(0.99);
  s.max_us = samples.back();
  return s;
}

}  // namespace shapectl
