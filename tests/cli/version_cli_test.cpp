// `shapectl --version`: the version and the git revision it was built from.
#include <gtest/gtest.h>

#include <regex>

#include "support/test_support.hpp"

namespace shapectl::test {
namespace {

TEST(VersionCli, PrintsTheVersionAndTheGitRevisionAndExitsZero) {
  const CliRun run = run_cli({"--version"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  // "shapectl 0.3.0 (git 1a2b3c4d5e6f)", "-modified" when built from a changed tree, "unknown"
  // outside a git checkout.
  EXPECT_TRUE(std::regex_search(
      run.out, std::regex(R"(^shapectl \d+\.\d+\.\d+ \(git ([0-9a-f]{12}(-modified)?|unknown)\))")))
      << run.out;
}

}  // namespace
}  // namespace shapectl::test
