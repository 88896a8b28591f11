// The link's decisions (feedback filter + supervisor, exactly what EgmLink does per datagram,
// including replies held back until they surely land after a tick) against adversarial
// feedback timing, in SIMULATED time. A controller model ticks every T: at tick m it applies
// the newest reply it has received (its commanded pose P(m)) and sends a datagram stamped mT
// with the arm's pose. The network on the way to us stalls for 20–90 ms and then delivers in
// a burst, duplicates, reorders, jitters, and a second sender chimes in; replies travel back
// in order with 0.1–0.3 ms latency. Some runs start with a joint measured beyond its hard
// limit or inside the margin. Checked:
//   1. every command inside the hard limits; from the margin only inwards;
//   2. on the controller's own 4 ms grid, at every tick: |P(m) − P(m−1)| ≤ v·T; and at every
//      tick that received a new command, |P(m) − 2P(m−1) + P(m−2)| ≤ a·T². A tick that
//      received nothing (its feedback stalled or came too late) holds the previous pose: no
//      sensor can prevent that stop, so only the restart after it is checked (from rest);
//   3. real time, on our clock: over any window of W seconds, |q(t+W) − q(t)| ≤ v·(W + 2T).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <random>

#include <shapectl/link/feedback_filter.hpp>
#include <shapectl/link/link_supervisor.hpp>

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
  int tick = 0;  // the controller tick that sent it; -1: the intruder's own
  Eigen::VectorXd joints;
};

struct Sent {
  double t;  // when it left us
  Eigen::VectorXd q;
  bool advanced;  // the link's word; a repeat must be the previous command exactly
};

struct Delivered {
  double t;  // when it reached the controller
  Eigen::VectorXd q;
};

// One seeded scenario: what the link sent and what reached the controller, per channel.
struct Scenario {
  explicit Scenario(unsigned seed) : rng(seed) {}

  std::mt19937 rng;
  double unit() { return std::uniform_real_distribution<double>(0, 1)(rng); }

  void run(double duration) {
    LinkSupervisor s("test", {"a0", "a1", "b0", "b1"}, {{"a", {0, 1}}, {"b", {2, 3}}},
                     Eigen::Vector4d::Constant(-hard), Eigen::Vector4d::Constant(hard),
                     full_limits(), {.watchdog_timeout = 0.1, .max_tracking_error = 10});
    std::vector<FeedbackFilter> filters(2);
    // The arms' poses before any command reaches them (set by hand).
    hand = std::vector<Eigen::VectorXd>(2, Eigen::Vector2d(0.3, -0.2));
    if (unit() < 0.3) hand[0][1] = -(hard + 0.05), start_outside = true;  // beyond the limit
    if (unit() < 0.3) hand[1][0] = hard - 0.04;                           // in the margin

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
    const int ticks = static_cast<int>(duration / T);
    for (int k = 1; k <= ticks; ++k)
      for (int c = 0; c < 2; ++c) {
        Datagram d{k * T + 1e-4 + unit() * 3e-4,      c, controller, static_cast<std::uint32_t>(k),
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
          Datagram x{d.deliver + unit() * T,
                     c,
                     intruder,
                     d.seqno + 3,
                     d.tm + 12,
                     -1,
                     Eigen::Vector2d(1.5 * unit() - 0.75, 1.5 * unit() - 0.75)};
          queue.push_back(x);
        }
      }
    std::stable_sort(queue.begin(), queue.end(),
                     [](const Datagram& x, const Datagram& y) { return x.deliver < y.deliver; });

    // Replies waiting to leave (held back by the link), per channel, in order.
    struct Pending {
      double at;
      Eigen::VectorXd q;
      bool advanced;
    };
    std::vector<std::deque<Pending>> pending(2);
    auto leave = [&](int c, const Pending& p) {
      sent[c].push_back({p.at, p.q, p.advanced});
      auto& d = delivered[c];
      const double arrive = std::max(p.at + 1e-4 + unit() * 2e-4, d.empty() ? 0.0 : d.back().t);
      d.push_back({arrive, p.q});
    };
    auto leave_until = [&](double t) {
      for (int c = 0; c < 2; ++c)
        for (auto& q = pending[static_cast<std::size_t>(c)]; !q.empty() && q.front().at <= t;
             q.pop_front())
          leave(c, q.front());
    };

    Eigen::VectorXd target(4);
    target << 0.3, -0.2, 0.3, -0.2;
    double next_target = 0.05, next_arm = 0.02, next_watchdog = 0.001;
    for (const Datagram& d : queue) {
      leave_until(d.deliver);
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
      // After 0.2 s the operator jogs a joint beyond its limit back into the margin (no
      // command can have reached that arm yet: none is sent while it is outside).
      if (start_outside && !jogged && d.deliver > 0.2) {
        hand[0][1] = -(hard - 0.05);
        jogged = true;
      }
      const Eigen::VectorXd measured = d.tick >= 0 ? pose(d.channel, d.tick * T) : d.joints;
      FeedbackFilter& f = filters[static_cast<std::size_t>(d.channel)];
      if (!s.connected(d.channel)) f.forget_sequence();
      if (f.accept(d.sender, d.seqno, d.tm) != FeedbackVerdict::accepted) continue;
      const FeedbackStep step =
          s.on_feedback(d.channel, measured, "", d.deliver, f.controller_time());
      if (!step.send) continue;
      Pending p{step.send_at, s.command(d.channel), step.advanced};
      auto& q = pending[static_cast<std::size_t>(d.channel)];
      if (q.empty() && p.at <= d.deliver) leave(d.channel, p);
      else q.push_back(p), ++held_back;
    }
    leave_until(std::numeric_limits<double>::infinity());
    for (int c = 0; c < 2; ++c) foreign += filters[static_cast<std::size_t>(c)].counts().foreign;
  }

  // The controller's commanded pose at time t: the newest reply received before t.
  Eigen::VectorXd pose(int c, double t) const {
    const auto it = delivered.find(c);
    if (it == delivered.end()) return hand[static_cast<std::size_t>(c)];
    const auto& d = it->second;
    auto after = std::lower_bound(d.begin(), d.end(), t,
                                  [](const Delivered& e, double x) { return e.t < x; });
    return after == d.begin() ? hand[static_cast<std::size_t>(c)] : std::prev(after)->q;
  }
  // Whether a reply reached the controller in the cycle before tick m.
  bool fresh(int c, int m) const {
    const auto& d = delivered.at(c);
    auto it = std::lower_bound(d.begin(), d.end(), (m - 1) * T,
                               [](const Delivered& e, double x) { return e.t < x; });
    return it != d.end() && it->t < m * T;
  }

  static GovernorLimits full_limits() {
    GovernorLimits l;
    l.lower = Eigen::Vector4d::Constant(-(hard - margin));
    l.upper = Eigen::Vector4d::Constant(hard - margin);
    l.velocity = Eigen::Vector4d::Constant(v_max);
    l.acceleration = Eigen::Vector4d::Constant(a_max);
    return l;
  }

  bool start_outside = false, jogged = false, armed_outside = false, refused_outside = false;
  std::vector<Eigen::VectorXd> hand;
  std::map<int, std::vector<Sent>> sent;
  std::map<int, std::vector<Delivered>> delivered;
  std::uint64_t foreign = 0, held_back = 0;
};

// The command in effect at `t` on our side (the first one before it).
Eigen::VectorXd at(const std::vector<Sent>& s, double t) {
  auto it =
      std::upper_bound(s.begin(), s.end(), t, [](double x, const Sent& e) { return x < e.t; });
  return it == s.begin() ? s.front().q : std::prev(it)->q;
}

TEST(AdversarialTiming, CommandsKeepTheLimitsOnTheControllersTicksWhateverTheFeedbackTiming) {
  int moving_runs = 0, outside_starts = 0, refused_outside = 0, held_ticks = 0;
  std::uint64_t held_back = 0;
  double fastest_tick = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Scenario sc(seed);
    sc.run(3.0);
    EXPECT_FALSE(sc.armed_outside) << "armed with a joint beyond its hard limit";
    outside_starts += sc.start_outside;
    refused_outside += sc.refused_outside;
    held_back += sc.held_back;
    EXPECT_GT(sc.foreign, 0u);
    for (int c = 0; c < 2; ++c) {
      const std::vector<Sent>& s = sc.sent[c];
      ASSERT_FALSE(s.empty());
      // 1. Hard limits; outside the band only ever inwards; a repeat repeats.
      Eigen::VectorXd prev = s.front().q;
      for (const Sent& e : s) {
        if (!e.advanced) {
          ASSERT_TRUE((e.q - prev).isZero(0)) << "a repeat moved, t " << e.t;
        }
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
      // 2. The controller's grid, from the first tick a command is in effect.
      const int first = static_cast<int>(std::floor(sc.delivered[c].front().t / T)) + 1;
      const int last = static_cast<int>(std::floor(sc.delivered[c].back().t / T)) + 1;
      for (int m = first + 2; m <= last; ++m) {
        const Eigen::VectorXd p0 = sc.pose(c, m * T), p1 = sc.pose(c, (m - 1) * T),
                              p2 = sc.pose(c, (m - 2) * T);
        const double speed = (p0 - p1).cwiseAbs().maxCoeff();
        fastest_tick = std::max(fastest_tick, speed / T);
        ASSERT_LE(speed, v_max * T + tol) << "tick " << m;
        if (!sc.fresh(c, m)) {
          ++held_ticks;
          continue;
        }
        ASSERT_LE((p0 - 2 * p1 + p2).cwiseAbs().maxCoeff(), a_max * T * T + tol) << "tick " << m;
      }
      // 3. Real time on our side, every 0.1 ms grid offset.
      const double end = s.back().t + 3 * T;
      for (const double W : {T, 5 * T, 25 * T}) {
        double worst = 0;
        for (double t = s.front().t; t + W <= end; t += 1e-4)
          worst = std::max(worst, (at(s, t + W) - at(s, t)).cwiseAbs().maxCoeff());
        EXPECT_LE(worst, v_max * (W + 2 * T) + tol) << "window " << W << " s";
      }
      if ((s.back().q - s.front().q).cwiseAbs().maxCoeff() > 0.1) ++moving_runs;
    }
  }
  // Not vacuous: the arms moved at full speed, ticks were held and restarted, replies were
  // held back, and the starts beyond the limits happened.
  EXPECT_GT(moving_runs, 60);
  EXPECT_GT(fastest_tick, 0.99 * v_max);
  EXPECT_GT(held_ticks, 100);
  EXPECT_GT(held_back, 20u);
  EXPECT_GE(outside_starts, 5);
  EXPECT_EQ(refused_outside, outside_starts);
}

}  // namespace
}  // namespace shapectl
