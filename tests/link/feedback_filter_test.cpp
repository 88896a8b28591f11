// Which feedback datagrams may drive the link: the bound sender, newest first; what is lost.
#include <gtest/gtest.h>

#include <shapectl/link/feedback_filter.hpp>

namespace shapectl {
namespace {

constexpr std::uint64_t controller = 7, intruder = 9;
using V = FeedbackVerdict;

TEST(FeedbackFilter, BindsToTheFirstSenderAndIgnoresOthers) {
  FeedbackFilter f;
  EXPECT_EQ(f.accept(controller, 1, 4), V::accepted);
  EXPECT_EQ(f.accept(intruder, 2, 8), V::foreign);
  EXPECT_EQ(f.accept(intruder, 500, 2000), V::foreign);
  EXPECT_EQ(f.accept(controller, 2, 8), V::accepted);  // the intruder's numbers changed nothing
  EXPECT_EQ(f.counts().foreign, 2u);
  EXPECT_EQ(f.counts().stale, 0u);
  f.forget_sequence();  // after a feedback loss the binding stays
  EXPECT_EQ(f.accept(intruder, 1, 4), V::foreign);
}

TEST(FeedbackFilter, DuplicatesAndOlderDatagramsAreStale) {
  FeedbackFilter f;
  EXPECT_EQ(f.accept(controller, 10, 40), V::accepted);
  EXPECT_EQ(f.accept(controller, 10, 40), V::stale);  // duplicate
  EXPECT_EQ(f.accept(controller, 9, 36), V::stale);   // older
  EXPECT_EQ(f.accept(controller, 11, 36), V::stale);  // newer number, time stamp going back
  EXPECT_EQ(f.accept(controller, 11, 44), V::accepted);
  EXPECT_EQ(f.counts().stale, 3u);
  EXPECT_EQ(f.counts().lost, 0u);
}

TEST(FeedbackFilter, ReorderingIsNotLossButAMissingNumberIs) {
  FeedbackFilter f;
  f.accept(controller, 1, 4);
  EXPECT_EQ(f.accept(controller, 3, 12), V::accepted);
  EXPECT_EQ(f.counts().lost, 1u);                   // 2 missing so far
  EXPECT_EQ(f.accept(controller, 2, 8), V::stale);  // it was only late
  EXPECT_EQ(f.counts().lost, 0u);
  EXPECT_EQ(f.accept(controller, 2, 8), V::stale);  // and a duplicate of it changes nothing
  EXPECT_EQ(f.counts().lost, 0u);
  EXPECT_EQ(f.accept(controller, 6, 24), V::accepted);
  EXPECT_EQ(f.counts().lost, 2u);  // 4 and 5
  EXPECT_EQ(f.counts().stale, 2u);
}

TEST(FeedbackFilter, SequenceNumbersWrapAndARestartedCounterCountsNothing) {
  FeedbackFilter f;
  f.accept(controller, 0xFFFFFFFEu, 0xFFFFFFF0u);
  EXPECT_EQ(f.accept(controller, 0xFFFFFFFFu, 0xFFFFFFF4u), V::accepted);
  EXPECT_EQ(f.accept(controller, 0, 0xFFFFFFF8u), V::accepted);
  EXPECT_EQ(f.accept(controller, 1, 0xFFFFFFFCu), V::accepted);
  EXPECT_EQ(f.counts().lost, 0u);
  EXPECT_EQ(f.accept(controller, 100000, 400000), V::accepted);  // a jump, not 99,998 lost
  EXPECT_EQ(f.counts().lost, 0u);
  // After a feedback loss the controller may start again from 1.
  EXPECT_EQ(f.accept(controller, 1, 4), V::stale);
  f.forget_sequence();
  EXPECT_EQ(f.accept(controller, 1, 4), V::accepted);
}

}  // namespace
}  // namespace shapectl
