#include <shapectl/server/log_limiter.hpp>

namespace shapectl::server {

bool LogLimiter::admit(Clock::time_point now, int& dropped) {
  dropped = 0;
  if (!started_ || now - window_start_ >= window_) {
    dropped = refused_;
    started_ = true;
    window_start_ = now;
    written_ = 0;
    refused_ = 0;
  }
  if (written_ < max_lines_) {
    ++written_;
    return true;
  }
  ++refused_;
  return false;
}

int LogLimiter::take_dropped(Clock::time_point now) {
  if (!started_ || now - window_start_ < window_) return 0;
  const int dropped = refused_;
  refused_ = 0;
  return dropped;
}

}  // namespace shapectl::server
