#include <shapectl/link/motion_pacing.hpp>

#include <algorithm>
#include <cmath>

namespace shapectl {

MotionPacer::MotionPacer(double period) : period_(period) { restart(); }

void MotionPacer::restart() {
  has_offset_ = false;
  has_landing_ = false;
  credit_ = 2 * period_;
}

PaceStep MotionPacer::on_feedback(double now, double controller_time) {
  const double T = period_;
  const double sample = now - controller_time;
  if (!has_offset_) {
    has_offset_ = true;
    offset_ = sample;
    last_send_ = now;
  } else {
    offset_ = std::min(offset_ + clock_drift * std::max(now - last_arrival_, 0.0), sample);
  }
  last_arrival_ = now;

  PaceStep step;
  step.send_at = std::max(now, last_send_);
  // The controller's time when the reply leaves, at the earliest; its ticks are the stamp + kT.
  const double tau = step.send_at - offset_;
  double tick = controller_time + T * (std::floor((tau - controller_time) / T) + 1);
  if (tick - tau < latency_allowance(T)) {  // could land on either side of `tick`: wait past it
    step.send_at += tick - tau;
    tick += T;
  }
  step.lands_at = tick;
  credit_ = std::min(credit_ + (step.send_at - last_send_), 2 * T);
  last_send_ = step.send_at;

  const double gap = has_landing_ ? tick - last_landing_ : T;
  if (gap < T / 2) return step;  // this tick already has its command: repeat it
  if (credit_ < 0) return step;  // stamps running ahead of real time
  credit_ -= T;
  step.advance = true;
  step.from_rest = !has_landing_ || gap > 1.5 * T;
  last_landing_ = tick;
  has_landing_ = true;
  return step;
}

}  // namespace shapectl
