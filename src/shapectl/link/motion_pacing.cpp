#include <shapectl/link/motion_pacing.hpp>

#include <algorithm>
#include <limits>

namespace shapectl {

MotionPacer::MotionPacer(double period) : period_(period) { restart(); }

void MotionPacer::restart() {
  credit_ = period_ + pacing_jitter(period_);
  last_send_ = -std::numeric_limits<double>::infinity();
}

PaceStep MotionPacer::on_send(double now) {
  const double jitter = pacing_jitter(period_);
  const double elapsed = now - last_send_;
  last_send_ = std::max(last_send_, now);
  PaceStep step;
  step.from_rest = elapsed > stall_cycles * period_;
  // A clock going backwards (it does not; monotonic) earns nothing.
  credit_ = std::min(credit_ + std::max(elapsed, 0.0), period_ + jitter);
  if (credit_ >= period_ - jitter) {
    credit_ -= period_;
    step.advance = true;
  }
  return step;
}

}  // namespace shapectl
