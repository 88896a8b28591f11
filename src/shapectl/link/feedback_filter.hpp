#pragma once
// Which EGM feedback datagrams of one channel may drive the link: from the controller the
// channel is bound to (the first sender heard; others are ignored for the link's lifetime),
// and newer than every one accepted before (sequence number ahead, time stamp not behind).
// Duplicates and reordered or old datagrams are ignored as stale. Lost = sequence numbers
// skipped and not seen since: one that arrives late (within 64 of the newest) is stale, not
// lost. Sequence numbers wrap (serial arithmetic); a jump of 1000 or more counts nothing
// (a restarted counter).
#include <cstdint>

namespace shapectl {

enum class FeedbackVerdict { accepted, foreign, stale };

struct FeedbackCounts {
  std::uint64_t foreign = 0;  // from another sender than the bound controller
  std::uint64_t stale = 0;    // duplicates, reordered, older than the newest
  std::uint64_t lost = 0;     // skipped sequence numbers never seen
};

class FeedbackFilter {
 public:
  // `sender`: the source address as one number (e.g. IPv4 << 16 | port).
  FeedbackVerdict accept(std::uint64_t sender, std::uint32_t seqno, std::uint32_t tm);
  // The controller may have restarted its counters (feedback was lost): the next datagram
  // from the bound sender starts a new sequence. The binding stays.
  void forget_sequence() { has_sequence_ = false; }

  const FeedbackCounts& counts() const { return counts_; }
  bool bound() const { return bound_; }
  // The newest accepted datagram's time stamp, unwrapped, in seconds of the controller's clock
  // (counted from the first datagram of the current sequence).
  double controller_time() const { return static_cast<double>(newest_time_ms_) * 1e-3; }
  // The controller's cycle seen in the newest datagram: its stamp minus the previous one's
  // when their sequence numbers are consecutive, ms; 0 when not known.
  std::int64_t cycle_ms() const { return cycle_ms_; }
  std::uint64_t sender() const { return sender_; }

 private:
  static constexpr int window = 64;
  bool bound_ = false;
  std::uint64_t sender_ = 0;
  bool has_sequence_ = false;
  std::uint32_t newest_ = 0, newest_tm_ = 0;
  std::int64_t newest_time_ms_ = 0;  // newest_tm_ unwrapped
  std::int64_t cycle_ms_ = 0;
  std::uint64_t seen_ = 0;  // bit d: newest − d was accepted or seen late
  FeedbackCounts counts_;
};

}  // namespace shapectl
