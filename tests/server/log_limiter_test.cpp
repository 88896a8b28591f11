#include <shapectl/server/log_limiter.hpp>

#include <gtest/gtest.h>

namespace shapectl::server {
namespace {

using namespace std::chrono_literals;

TEST(LogLimiter, AFloodWritesAFixedNumberOfLinesPerWindowAndCountsTheRest) {
  LogLimiter limiter(10, 1s);
  const LogLimiter::Clock::time_point start{};  // simulated time
  int written = 0, dropped = 0, reported = 0;
  for (int k = 0; k < 100000; ++k) {  // 100,000 lines over 10 simulated seconds
    if (limiter.admit(start + std::chrono::microseconds(100) * k, dropped)) ++written;
    reported += dropped;
  }
  EXPECT_EQ(written, 100);
  EXPECT_EQ(reported, 100000 - 100 - 9990) << "every closed window reports its refusals";
  EXPECT_EQ(limiter.take_dropped(start + 9900ms), 0) << "the last window is still open";
  EXPECT_EQ(limiter.take_dropped(start + 11s), 9990);
  EXPECT_EQ(limiter.take_dropped(start + 12s), 0) << "reported once";
}

}  // namespace
}  // namespace shapectl::server
