// The session log: lines written as they happen, read back with places in errors.
#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

TEST(SessionLog, EveryLineIsOnDiskAsSoonAsItIsWritten) {
  test::TempDir dir;
  const auto file = dir.path() / "s.jsonl";
  SessionLog log(file);
  log.write("targets", {{"nodes", {1, 2}}});
  // Read while the log is still open: the line is there.
  const auto events = read_session_log(file);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].event, "targets");
  EXPECT_EQ(events[0].fields["nodes"][1], 2);
  EXPECT_GE(events[0].t, 0);
}

TEST(SessionLog, ALineCutShortByACrashIsSkipped) {
  test::TempDir dir;
  const auto file =
      dir.write("s.jsonl", "{\"t\":0,\"event\":\"a\"}\n{\"t\":1,\"event\":\"b\",\"jo");
  int truncated = 0;
  const auto events = read_session_log(file, &truncated);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(truncated, 1);
}

TEST(SessionLog, ABadLineInTheMiddleNamesItsLine) {
  test::TempDir dir;
  const auto file =
      dir.write("s.jsonl", "{\"t\":0,\"event\":\"a\"}\nnot json\n{\"t\":1,\"event\":\"b\"}\n");
  try {
    read_session_log(file);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.jsonl:2:"), std::string::npos) << e.what();
  }
}

TEST(SessionLog, UnwritablePlaceIsAnInputError) {
  EXPECT_THROW(SessionLog("/nonexistent/dir/s.jsonl"), InputError);
}

}  // namespace
}  // namespace shapectl
