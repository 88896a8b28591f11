#pragma once
// When a reply to a feedback datagram may advance the motion governor, and when it leaves:
// one governor step per controller cycle that the reply lands on, never per datagram.
//
// The controller (EGM) ticks every T seconds: at each tick it sends its feedback, stamped with
// its own clock, and applies the newest command it has received. So what the robot sees is
// the sequence of commands in effect at its ticks. To keep that sequence within the governor's
// limits (|Δq| ≤ v·T, |Δ²q| ≤ a·T² per tick), each reply must carry the governor's pose for the
// tick it lands on:
// - The controller's clock is estimated from the time stamps: offset = min over datagrams of
//   (arrival − stamp), so `now − offset` is the earliest the controller's time can be now.
//   The minimum may rise slowly (`clock_drift`) to follow a drifting controller clock.
// - A reply reaches the controller within `latency_allowance` of that estimate (the network's
//   latency beyond its fastest datagram, both ways). It lands on the first tick after it
//   arrives. A reply that could land on either side of a tick is held back until it is surely
//   past that tick (at most the allowance): then the tick it lands on is known.
// - One governor step per landing tick: the first reply for a tick advances, later replies for
//   the same tick repeat that command. A reply landing two or more ticks after the last one
//   (the controller held our previous command meanwhile: a lost or late datagram, a stall)
//   advances from rest. A burst after an 80 ms stall therefore moves one step, from rest.
// - Backstop against a controller whose stamps lie: a real-time credit c (capped at 2T) that
//   each step spends T of; steps need c ≥ 0. Over any real interval W, whatever the stamps,
//   the governor moves at most v·(W + 3T).
// What stays outside any sensor's control: a tick that receives no new command (feedback or
// reply lost, stalled or too late) holds the previous one, i.e. the commanded pose stops for
// that tick. The next command then starts from rest.
namespace shapectl {

// How much later than the fastest datagram a reply may reach the controller, as a fraction
// of the period: T/8 = 0.5 ms at 4 ms.
inline double latency_allowance(double period) { return period / 8; }
// How fast the clock offset estimate may rise (controller clock slower than ours), s/s.
constexpr double clock_drift = 1e-4;

struct PaceStep {
  bool advance = false;    // take one governor step of `period`; else resend the last command
  bool from_rest = false;  // zero the governor's velocity first
  double send_at = 0;   // when to send the reply (s, our clock): now, or up to the allowance later
  double lands_at = 0;  // the controller tick it lands on (s, controller clock)
};

class MotionPacer {
 public:
  explicit MotionPacer(double period);
  // A feedback datagram stamped `controller_time` (s, the controller's clock) arrived at
  // `now` (s, our monotonic clock); the reply is to be sent.
  PaceStep on_feedback(double now, double controller_time);
  // Forget the past (e.g. feedback reappeared): the next reply advances from rest.
  void restart();

 private:
  double period_;
  bool has_offset_ = false;
  double offset_ = 0;  // min(arrival − stamp), our clock minus the controller's
  double last_arrival_ = 0;
  double last_send_ = 0;     // replies leave in order
  double last_landing_ = 0;  // controller clock
  bool has_landing_ = false;
  double credit_ = 0;
};

}  // namespace shapectl
