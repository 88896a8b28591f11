#include <shapectl/link/egm_simulator.hpp>

#include <array>
#include <chrono>
#include <deque>
#include <string>

namespace shapectl {

struct EgmSimulator::Arm {
  std::optional<UdpSocket> socket;
  sockaddr_in sensor{};
  SimRobot robot;
  EgmSimArmStats stats;
  std::uint32_t seqno = 0;
  std::vector<ArmJoints> recent;  // up to two previous commands, for the checks
  bool resumed = false;
  // Replies received after the tick being processed (the thread woke late): the next tick's.
  std::deque<std::pair<double, std::string>> later;
};

GovernorLimits yumi_arm_limits(double acceleration) {
  // Axes 1, 2, 7, 3: 180 deg/s; 4, 5, 6: 400 deg/s.
  GovernorLimits g;
  g.lower.resize(7), g.upper.resize(7), g.velocity.resize(7);
  g.lower << -2.94087978961, -2.50454747661, -2.94087978961, -2.15548162621, -5.06145483078,
      -1.53588974176, -3.99680398707;
  g.upper << 2.94087978961, 0.759218224618, 2.94087978961, 1.3962634016, 5.06145483078,
      2.40855436775, 3.99680398707;
  g.velocity << 3.14159265359, 3.14159265359, 3.14159265359, 3.14159265359, 6.98131700798,
      6.98131700798, 6.98131700798;
  g.acceleration = Eigen::VectorXd::Constant(7, acceleration);
  return g;
}

EgmSimulator::EgmSimulator(EgmSimulatorConfig config) : config_(std::move(config)) {
  const std::array<int, 2> ports = {config_.left_port, config_.right_port};
  const std::array<ArmJoints, 2> initial = {config_.left_initial, config_.right_initial};
  for (int a = 0; a < 2; ++a) {
    auto arm =
        std::make_unique<Arm>(Arm{std::nullopt,
                                  {},
                                  SimRobot(yumi_arm_limits(config_.acceleration), initial[a]),
                                  {},
                                  0,
                                  {},
                                  false,
                                  {}});
    if (ports[a] > 0) {
      arm->sensor = ipv4_address(config_.sensor_address, ports[a], "egm-sim sensor address");
      arm->socket.emplace("0.0.0.0", 0, "egm-sim");
      arm->socket->record_arrival_times();
      arm->stats.present = true;
    }
    arm->stats.position = initial[a];
    arms_.push_back(std::move(arm));
  }
}

EgmSimulator::~EgmSimulator() { stop(); }

void EgmSimulator::start() {
  if (!thread_.joinable()) thread_ = std::jthread([this](std::stop_token s) { run(s); });
}

void EgmSimulator::stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  thread_.join();
}

void EgmSimulator::set_paused(bool paused) { paused_ = paused; }

EgmSimArmStats EgmSimulator::stats(int arm) const {
  std::lock_guard lock(mutex_);
  return arms_[static_cast<std::size_t>(arm)]->stats;
}

void EgmSimulator::run(std::stop_token stop) {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(config_.period));
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  bool was_paused = false;
  while (!stop.stop_requested()) {
    next += period;
    std::this_thread::sleep_until(next);
    // A real controller's cycle is exact; this thread may wake late on a busy machine. The
    // tick still uses only the replies that arrived before its exact time (kernel receive
    // times), so commands land on the ticks they would on a controller. A very late tick is
    // not checked.
    const auto woke = std::chrono::steady_clock::now();
    const bool late = woke - next > period / 2;
    const double tick_time =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch() -
                                      (woke - next))
            .count();
    const bool paused = paused_;
    for (auto& arm : arms_) {
      if (!arm->socket) continue;
      if (was_paused && !paused) arm->resumed = true;
      tick(*arm, paused, late, tick_time);
    }
    was_paused = paused;
  }
}

void EgmSimulator::tick(Arm& arm, bool paused, bool late, double tick_time) {
  const GovernorLimits limits = yumi_arm_limits(config_.acceleration);
  std::array<char, EgmCodec::max_datagram + 1> buffer;
  // Replies to earlier feedback: the newest valid one is the arm's command, as on a real
  // controller, which uses the latest correction each cycle.
  std::optional<ArmJoints> newest;
  long n;
  double arrived = 0;
  while ((n = arm.socket->receive(buffer, nullptr, &arrived)) >= 0) {
    const auto size = static_cast<std::size_t>(std::min<long>(n, static_cast<long>(buffer.size())));
    arm.later.emplace_back(arrived, std::string(buffer.data(), size));
  }
  for (; !arm.later.empty() && arm.later.front().first <= tick_time; arm.later.pop_front()) {
    const std::string& bytes = arm.later.front().second;
    EgmCommand command;
    std::lock_guard lock(mutex_);
    if (!codec_.decode_sensor(bytes, command, nullptr)) {
      ++arm.stats.rejected;
      continue;
    }
    ++arm.stats.commands;
    const ArmJoints& q = command.joints;
    if ((q.array() < limits.lower.array()).any() || (q.array() > limits.upper.array()).any())
      ++arm.stats.outside_limits;
    newest = q;
  }
  std::lock_guard lock(mutex_);
  EgmSimArmStats& s = arm.stats;
  // The checks cover runs of cycles that each brought a new command; a cycle without one (the
  // link held or its reply came late) restarts them, as does our own late tick.
  if (arm.resumed || !newest || (!arm.recent.empty() && *newest == arm.recent.back()) || late)
    arm.recent.clear(), arm.resumed = false;
  if (newest) {
    const ArmJoints& q = *newest;
    s.last_command = q;
    const double dt = config_.period;
    if (!arm.recent.empty())
      s.max_speed = std::max(s.max_speed, (q - arm.recent.back()).cwiseAbs().maxCoeff() / dt);
    if (arm.recent.size() == 2)
      s.max_acceleration =
          std::max(s.max_acceleration,
                   (q - 2 * arm.recent.back() + arm.recent.front()).cwiseAbs().maxCoeff() /
                       (dt * dt));
    if (arm.recent.size() == 2) arm.recent.erase(arm.recent.begin());
    arm.recent.push_back(q);
    arm.robot.command(q);
  }
  arm.robot.step(config_.period);
  s.position = arm.robot.position();
  if (paused) return;
  EgmFeedback feedback;
  feedback.joints = s.position;
  feedback.seqno = ++arm.seqno;
  feedback.tm = static_cast<std::uint32_t>(arm.seqno * config_.period * 1000);
  feedback.motors_on = feedback.egm_running = feedback.rapid_running = true;
  ++s.feedback_sent;
  arm.socket->send_to(codec_.encode_robot(feedback), arm.sensor);
}

}  // namespace shapectl
