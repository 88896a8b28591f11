#include <shapectl/link/feedback_filter.hpp>

namespace shapectl {

namespace {

// b − a in serial-number arithmetic: positive when b is ahead.
std::int64_t ahead(std::uint32_t a, std::uint32_t b) { return static_cast<std::int32_t>(b - a); }

}  // namespace

FeedbackVerdict FeedbackFilter::accept(std::uint64_t sender, std::uint32_t seqno,
                                       std::uint32_t tm) {
  if (!bound_) bound_ = true, sender_ = sender;
  if (sender != sender_) return ++counts_.foreign, FeedbackVerdict::foreign;
  if (!has_sequence_) {
    has_sequence_ = true;
    newest_ = seqno, newest_tm_ = tm, seen_ = 1;
    newest_time_ms_ = tm;
    cycle_ms_ = 0;
    return FeedbackVerdict::accepted;
  }
  const std::int64_t d = ahead(newest_, seqno);
  if (d <= 0) {
    const std::int64_t back = -d;
    if (back < window && !(seen_ >> back & 1)) {
      // It was counted lost when a newer one came first: it was only late.
      seen_ |= std::uint64_t{1} << back;
      if (counts_.lost > 0) --counts_.lost;
    }
    return ++counts_.stale, FeedbackVerdict::stale;
  }
  if (ahead(newest_tm_, tm) < 0) return ++counts_.stale, FeedbackVerdict::stale;
  if (d < 1000) counts_.lost += static_cast<std::uint64_t>(d - 1);
  seen_ = d >= window ? 1 : (seen_ << d | 1);
  cycle_ms_ = d == 1 ? ahead(newest_tm_, tm) : 0;
  newest_time_ms_ += ahead(newest_tm_, tm);
  newest_ = seqno, newest_tm_ = tm;
  return FeedbackVerdict::accepted;
}

}  // namespace shapectl
