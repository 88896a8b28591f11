// The link's decisions (feedback filter + supervisor, exactly what EgmLink does per datagram)
// against adversarial feedback timing, in SIMULATED time: a controller model sends one
// datagram per 4 ms cycle; the network stalls for 20–90 ms and then delivers in a burst,
// duplicates, reorders, jitters, and a second sender chimes in; some runs start with a joint
// measured beyond its hard limit or inside the margin. The commanded trajectory q(t) (the
// last command sent is in effect until the next) is then checked:
//   1. every command inside the hard limits; from the margin only inwards;
//   2. real time: over any window of W seconds (W = 4, 20, 100 ms, every grid offset
//      sampled), |q(t+W) − q(t)| ≤ v·(W + T + 2J): the link never runs ahead of the clock by
//      more than one cycle plus the jitter allowance J (why not v·W: see motion_pacing.hpp);
//   3. per controller cycle: consecutive advancing commands keep |Δq| ≤ v·T and
//      |Δq_k − Δq_{k−1}| ≤ a·T², where a hold of more than stall_cycles·T (20 ms) in between
//      counts as a stop (the controller held the pose, so motion must restart from rest).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include <shapectl/link/feedback_filter.hpp>
#include <shapectl/link/link_supervisor.hpp>
#include <shapectl/link/motion_pacing.hpp>

namespace shapectl {
namespace {

constexpr double T = 0.004;
constexpr double tol = 1e-12;
constexpr double hard = 2.0;    // joint limits ±2 rad
constexpr double margin = 0.1;  // band ±1.9 rad
constexpr double v_max = 0.5, a_max = 2.0;
constexpr std::uint64_t controller = 1, intruder = 2;

struct Datagram {
  double deliver = 0;  // s
  int channel = 0;
  std::uint64_t sender = controller;
  std::uint32_t seqno = 0, tm = 0;
  int cycle = 0;  // which controller cycle's pose it carries; -1: the intruder's own
  Eigen::VectorXd joints;
};

struct Sent {
  double t;
  Eigen::VectorXd q;
  bool advanced;  // the link's word; a hold must repeat the previous command exactly
};

// One seeded scenario; returns the commands sent per channel.
struct Scenario {
  explicit Scenario(unsigned seed) : rng(seed) {}

  std::mt19937 rng;
  double unit() { return std::uniform_real_distribution<double>(0, 1)(rng); }

  void run(double duration) {
    LinkSupervisor s("test", {"a0", "a1", "b0", "b1"}, {{"a", {0, 1}}, {"b", {2, 3}}},
                     Eigen::Vector4d::Constant(-hard), Eigen::Vector4d::Constant(hard),
                     full_limits(), {.watchdog_timeout = 0.1, .max_tracking_error = 10});
    std::vector<FeedbackFilter> filters(2);
    // Where each arm really is: it follows the last command received (instantly).
    std::vector<Eigen::VectorXd> pose(2, Eigen::Vector2d(0.3, -0.2));
    if (unit() < 0.3) pose[0][1] = -(hard + 0.05), start_outside = true;  // beyond the limit
    if (unit() < 0.3) pose[1][0] = hard - 0.04;                            // in the margin
    initial = pose;

    // The network's plan: stalls, then per datagram jitter, duplicates, reordering.
    std::vector<std::pair<double, double>> stalls;
    for (double t = 0.1; t < duration; t += 0.1 + unit() * 0.4)
      stalls.push_back({t, 0.02 + unit() * 0.07});
    auto stalled_until = [&](double t) {
      for (auto [s0, len] : stalls)
        if (t >= s0 && t < s0 + len) return s0 + len;
      return -1.0;
    };
    std::vector<Datagram> queue;
    const int cycles = static_cast<int>(duration / T);
    for (int k = 1; k <= cycles; ++k)
      for (int c = 0; c < 2; ++c) {
        Datagram d{k * T + 1e-4 + unit() * 3e-4, c, controller, static_cast<std::uint32_t>(k),
                   static_cast<std::uint32_t>(k * 4), k, {}};
        if (const double until = stalled_until(d.deliver); until > 0)
          d.deliver = until + 1e-6 * (k % 97);  // the burst, in order, within 0.1 ms
        if (unit() < 0.05) d.deliver += 0.002 + unit() * 0.006;  // reordered behind later ones
        queue.push_back(d);
        if (unit() < 0.05) {  // duplicated
          Datagram dup = d;
          dup.deliver += unit() * 0.001;
          queue.push_back(dup);
        }
        if (unit() < 0.03) {  // a second sender, newer sequence numbers, a pose of its own
          Datagram x{d.deliver + unit() * T, c, intruder, d.seqno + 3, d.tm + 12, -1,
                     Eigen::Vector2d(1.5 * unit() - 0.75, 1.5 * unit() - 0.75)};
          queue.push_back(x);
        }
      }
    std::stable_sort(queue.begin(), queue.end(),
                     [](const Datagram& x, const Datagram& y) { return x.deliver < y.deliver; });

    // The controller's pose at each cycle: recorded when the cycle's datagram is built, i.e.
    // lazily, from the commands delivered before that cycle's time.
    std::map<std::pair<int, int>, Eigen::VectorXd> pose_at;
    auto pose_of = [&](int c, int cycle) {
      auto it = pose_at.find({c, cycle});
      if (it != pose_at.end()) return it->second;
      return pose[static_cast<std::size_t>(c)];
    };
    int next_cycle_recorded = 1;
    auto record_poses_until = [&](double t) {
      for (; next_cycle_recorded * T <= t; ++next_cycle_recorded) {
        if (next_cycle_recorded * T > 0.2) jog_inside(pose);
        for (int c = 0; c < 2; ++c) pose_at[{c, next_cycle_recorded}] = pose[static_cast<std::size_t>(c)];
      }
    };

    Eigen::VectorXd target(4);
    target << 0.3, -0.2, 0.3, -0.2;
    double next_target = 0.05, next_arm = 0.02, next_watchdog = 0.001;
    for (const Datagram& d : queue) {
      // The link thread's 1 ms watchdog poll and the operator/optimizer in between.
      for (; next_watchdog <= d.deliver; next_watchdog += 0.001) s.check_watchdog(next_watchdog);
      if (d.deliver >= next_target) {
        for (int i = 0; i < 4; ++i) target[i] = (hard - 0.05) * (2 * unit() - 1);
        s.set_target(target, s.target_problem(target, true));
        next_target = d.deliver + 0.05 + unit() * 0.4;
      }
      if (d.deliver >= next_arm) {
        std::string why;
        const bool armed = s.arm(d.deliver, &why);
        if (start_outside && !jogged) (armed ? armed_outside : refused_outside) = true;
        next_arm = d.deliver + 0.05;
      }
      record_poses_until(d.deliver);
      const Eigen::VectorXd measured = d.cycle >= 0 ? pose_of(d.channel, d.cycle) : d.joints;
      FeedbackFilter& f = filters[static_cast<std::size_t>(d.channel)];
      if (!s.connected(d.channel)) f.forget_sequence();
      if (f.accept(d.sender, d.seqno, d.tm) != FeedbackVerdict::accepted) continue;
      const FeedbackStep step = s.on_feedback(d.channel, measured, "", d.deliver);
      if (!step.send) continue;
      sent[d.channel].push_back({d.deliver, s.command(d.channel), step.advanced});
      pose[static_cast<std::size_t>(d.channel)] = s.command(d.channel);
    }
    for (int c = 0; c < 2; ++c) foreign += filters[static_cast<std::size_t>(c)].counts().foreign;
  }

  static GovernorLimits full_limits() {
    GovernorLimits l;
    l.lower = Eigen::Vector4d::Constant(-(hard - margin));
    l.upper = Eigen::Vector4d::Constant(hard - margin);
    l.velocity = Eigen::Vector4d::Constant(v_max);
    l.acceleration = Eigen::Vector4d::Constant(a_max);
    return l;
  }
  // After 0.2 s the operator jogs a joint that is beyond its limit back into the margin.
  void jog_inside(std::vector<Eigen::VectorXd>& pose) {
    if (!start_outside || jogged) return;
    pose[0][1] = -(hard - 0.05);
    jogged = true;
  }

  bool start_outside = false, jogged = false, armed_outside = false, refused_outside = false;
  std::vector<Eigen::VectorXd> initial;
  std::map<int, std::vector<Sent>> sent;
  std::uint64_t foreign = 0;
};

// The command in effect at `t` (the initial measured pose before the first one).
Eigen::VectorXd at(const std::vector<Sent>& s, const Eigen::VectorXd& initial, double t) {
  auto it = std::upper_bound(s.begin(), s.end(), t, [](double x, const Sent& e) { return x < e.t; });
  return it == s.begin() ? initial : std::prev(it)->q;
}

TEST(AdversarialTiming, CommandsKeepTheLimitsInRealTimeWhateverTheFeedbackTiming) {
  const double J = pacing_jitter(T);
  int moving_runs = 0, outside_starts = 0, refused_outside = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Scenario sc(seed);
    sc.run(3.0);
    EXPECT_FALSE(sc.armed_outside) << "armed with a joint beyond its hard limit";
    outside_starts += sc.start_outside;
    refused_outside += sc.refused_outside;
    EXPECT_GT(sc.foreign, 0u);
    for (int c = 0; c < 2; ++c) {
      const std::vector<Sent>& s = sc.sent[c];
      ASSERT_FALSE(s.empty());
      // Nothing is commanded before the first command (a joint beyond its limit is jogged in
      // by hand meanwhile): the trajectory starts there.
      const Eigen::VectorXd q0 = s.front().q;
      // 1. Hard limits; outside the band only ever inwards.
      Eigen::VectorXd prev = q0;
      for (const Sent& e : s) {
        for (Eigen::Index i = 0; i < 2; ++i) {
          ASSERT_LE(std::abs(e.q[i]), hard) << "t " << e.t;
          const double out = std::max(0.0, std::abs(e.q[i]) - (hard - margin));
          const double out_before = std::max(0.0, std::abs(prev[i]) - (hard - margin));
          if (out > 0 && out_before > 0) {
            ASSERT_LE(out, out_before + tol) << "t " << e.t;
          }
        }
        prev = e.q;
      }
      // 2. Real time, every 0.1 ms grid offset.
      const double end = s.back().t + 3 * T;
      for (const double W : {T, 5 * T, 25 * T}) {
        const double bound = v_max * (W + T + 2 * J) + tol;
        double worst = 0;
        for (double t = s.front().t; t + W <= end; t += 1e-4)
          worst = std::max(worst, (at(s, q0, t + W) - at(s, q0, t)).cwiseAbs().maxCoeff());
        EXPECT_LE(worst, bound) << "window " << W << " s";
      }
      // 3. Per controller cycle, from rest after a stall.
      Eigen::VectorXd last = q0, last_step = Eigen::VectorXd::Zero(2);
      double last_sent = -1;
      bool held = true;
      for (const Sent& e : s) {
        if (last_sent >= 0 && e.t - last_sent > stall_cycles * T) held = true;
        last_sent = e.t;
        const Eigen::VectorXd step = e.q - last;
        if (!e.advanced) {
          ASSERT_TRUE(step.isZero(0)) << "a hold moved, t " << e.t;
          continue;
        }
        if (held) last_step.setZero();
        ASSERT_LE(step.cwiseAbs().maxCoeff(), v_max * T + tol) << "t " << e.t;
        ASSERT_LE((step - last_step).cwiseAbs().maxCoeff(), a_max * T * T + tol) << "t " << e.t;
        last = e.q, last_step = step, held = false;
      }
      if ((s.back().q - q0).cwiseAbs().maxCoeff() > 0.1) ++moving_runs;
    }
  }
  // The arms really moved and the starts beyond the limits happened: the checks were not vacuous.
  EXPECT_GT(moving_runs, 60);
  EXPECT_GE(outside_starts, 5);
  EXPECT_EQ(refused_outside, outside_starts);
}

}  // namespace
}  // namespace shapectl
