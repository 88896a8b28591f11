// The session log: lines written as they happen, read back with places in errors.
#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>

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

// Past its cap a log is rotated (LOG -> LOG.1 -> LOG.2, the oldest dropped): every file within
// the cap, and each one, the current one first, checkable on its own (its header repeated).
TEST(SessionLog, PastItsCapTheLogRotatesAndEveryFileStaysWithinItAndReplays) {
  test::TempDir dir;
  const auto file = dir.path() / "s.jsonl";
  const SessionLogLimits limits{.max_bytes = 20'000, .keep = 2};
  const int n = 7;
  const GovernorLimits governor{Eigen::VectorXd::Constant(n, -2), Eigen::VectorXd::Constant(n, 2),
                                Eigen::VectorXd::Constant(n, 0.5),
                                Eigen::VectorXd::Constant(n, 1.0)};
  const std::vector<std::string> names(n, "joint");
  {
    SessionLog log(file, limits);
    log.write_header("session", {{"scene", "scene.json"}, {"joint_names", names}});
    log_link_started(log, "sim", names, {{"robot", {0, 1, 2, 3, 4, 5, 6}}}, governor, 0.004);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
    // ~200 bytes a command: 100 kB, five times the cap.
    for (int k = 0; k < 500; ++k) {
      q.array() += 1e-4;
      log_command(log, "robot", static_cast<std::uint64_t>(k), q, q);
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "s.jsonl.3")) << "only two rotated files";
  for (const auto& f : {file, dir.path() / "s.jsonl.1", dir.path() / "s.jsonl.2"}) {
    ASSERT_TRUE(std::filesystem::exists(f)) << f;
    EXPECT_LE(std::filesystem::file_size(f), limits.max_bytes) << f;
    const auto events = read_session_log(f);
    ASSERT_GE(events.size(), 3u) << f;
    EXPECT_EQ(events[0].event, "session") << f;
    EXPECT_EQ(events[1].event, "link") << f;
    const CommandLogCheck check = check_command_log(events, f.string());
    EXPECT_EQ(check.scene, "scene.json");
    EXPECT_EQ(check.links, 1) << f;
    EXPECT_GT(check.commands, f == file ? 0 : 50) << f;
    EXPECT_TRUE(check.ok()) << check.violations.front();
  }
  // The newest command is in the current file.
  const auto last = read_session_log(file).back();
  EXPECT_EQ(last.fields["seq"], 499);
}

// A line larger than the cap is still written whole, in a file of its own after the header.
TEST(SessionLog, ALineLargerThanTheCapIsWrittenWhole) {
  test::TempDir dir;
  const auto file = dir.path() / "s.jsonl";
  {
    SessionLog log(file, {.max_bytes = 100, .keep = 1});
    log.write_header("session", {{"scene", "a.json"}});
    log.write("big", {{"text", std::string(500, 'x')}});
    log.write("small");
  }
  const auto rotated = read_session_log(dir.path() / "s.jsonl.1");
  ASSERT_EQ(rotated.size(), 2u);
  EXPECT_EQ(rotated[1].fields["text"].get<std::string>().size(), 500u);
  const auto current = read_session_log(file);
  ASSERT_EQ(current.size(), 2u);
  EXPECT_EQ(current[0].event, "session");
  EXPECT_EQ(current[1].event, "small");
}

TEST(SessionLog, UnwritablePlaceIsAnInputError) {
  EXPECT_THROW(SessionLog("/nonexistent/dir/s.jsonl"), InputError);
}

}  // namespace
}  // namespace shapectl
