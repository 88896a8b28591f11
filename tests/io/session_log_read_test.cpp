// Reading a session log (replay) is bounded like every other input: no hang, no flood.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

std::string read_error(const std::filesystem::path& file) {
  try {
    read_session_log(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SessionLogRead, AFifoIsRefusedInsteadOfWaitedOn) {
  test::TempDir dir;
  const auto fifo = dir.path() / "log.jsonl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string message = read_error(fifo);
  EXPECT_NE(message.find("log.jsonl"), std::string::npos) << message;
  EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
}

TEST(SessionLogRead, ADeeplyNestedLineIsAnErrorNamingItsLine) {
  test::TempDir dir;
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const auto file = dir.write("s.jsonl", "{\"t\":0,\"event\":\"a\"}\n" + deep + "\n");
  const std::string message = read_error(file);
  EXPECT_NE(message.find("s.jsonl:2:"), std::string::npos) << message.substr(0, 200);
  EXPECT_LT(message.size(), 400u) << "the bad line is echoed bounded";
}

}  // namespace
}  // namespace shapectl
