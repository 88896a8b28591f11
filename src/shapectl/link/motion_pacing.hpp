#pragma once
// When a feedback datagram may advance the motion governor: in real time, not per datagram.
//
// T = the controller cycle (egm_period), J = pacing_jitter(T) = T/4. A per-channel credit c
// holds real time not yet spent on motion, capped at T + J. Each command sent at time t,
// e = t − (time of the previous command sent):
//   c = min(c + e, T + J);  if c ≥ T − J: one governor step of exactly T, c −= T;
//                           else: hold (send the previous command again).
//   If e > stall_cycles·T (a stall, 20 ms) the controller held our previous command for
//   several cycles, so its reference stood still: the governor's velocity is zeroed first
//   (motion restarts from rest). A shorter hold (a lost datagram, a late thread) resumes at the
//   governor's velocity, as after any missed EGM cycle; restarting from rest there would make
//   every scheduling hiccup a stop-and-go.
// Hence c ∈ [−J, T + J], and over any real interval (t, s] with n advances
//   n·T ≤ c(t) − c(s) + (s − t) ≤ s − t + T + 2J,  so  |q(s) − q(t)| ≤ v·(s − t + T + 2J):
// bursts, duplicates with fresh numbers or floods cannot outrun the clock (an 80 ms stall
// delivered in one burst gives one step, not 20). Every advance is one exact governor step,
// so per controller cycle |Δq| ≤ v·T and |Δq_k − Δq_{k−1}| ≤ a·T² (from rest after a stall).
// Jitter up to J either way is absorbed without a hold (early: the credit dips below 0 and
// the next, later, datagram refills it).
//
// What no design can promise: |q(t+T) − q(t)| ≤ v·T on EVERY 4 ms grid. Commands are a
// staircase whose steps come when feedback arrives; sends at 0, 4.1 and 8.0 ms sampled at
// 4.05 and 8.05 ms show two steps in one window. Forbidding that means stuttering (0 and 2
// steps per controller cycle), which is worse for the robot. Likewise a feedback stall
// freezes the pose mid-motion whatever was sent, so no acceleration bound holds on a grid
// across a stall's onset; the restart from rest bounds the other end. On the controller's own
// grid a reply that arrives late (after the tick it was meant for) moves two steps at the next
// tick; only knowing which tick each reply lands on (from EGM's time stamps and the latency)
// could prevent that.
namespace shapectl {

inline double pacing_jitter(double period) { return period / 4; }
// A hold longer than this many cycles is a stall: motion restarts from rest.
constexpr int stall_cycles = 5;

struct PaceStep {
  bool advance = false;    // take one governor step of `period`; else resend the last command
  bool from_rest = false;  // zero the governor's velocity first
};

class MotionPacer {
 public:
  explicit MotionPacer(double period);
  // A command is about to be sent at `now` (s, monotonic clock).
  PaceStep on_send(double now);
  // Forget the past (e.g. feedback reappeared): the next send advances from rest.
  void restart();

 private:
  double period_;
  double credit_;
  double last_send_;
};

}  // namespace shapectl
