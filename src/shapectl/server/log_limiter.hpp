#pragma once
// Bounded logging for the server: at most `max_lines` lines per window; the rest are counted and
// the count is reported when the next window opens, so a flood (a client sending garbage, a
// failing accept()) costs a bounded amount of output. Time is passed in, so tests simulate it.
#include <chrono>

namespace shapectl::server {

class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  LogLimiter(int max_lines, Clock::duration window) : max_lines_(max_lines), window_(window) {}

  // Whether a line may be written at `now`. When this opens a new window, `dropped` is set to
  // the number of lines the previous window refused (else 0), for a "N lines suppressed" note.
  bool admit(Clock::time_point now, int& dropped);
  // The lines refused in a window that has ended by `now` (then forgotten), else 0: lets a
  // periodic caller report a flood that stopped.
  int take_dropped(Clock::time_point now);

 private:
  int max_lines_;
  Clock::duration window_;
  Clock::time_point window_start_{};
  bool started_ = false;
  int written_ = 0;
  int refused_ = 0;
};

}  // namespace shapectl::server
