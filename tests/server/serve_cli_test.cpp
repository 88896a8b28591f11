// `shapectl serve` refuses bad input before serving anything: exit 1 and a message saying where.
#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace shapectl::test {
namespace {

TEST(ServeCli, MissingSceneIsAnInputError) {
  TempDir dir;
  const CliRun r = run_cli({"serve", (dir.path() / "missing.json").string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
}

TEST(ServeCli, SceneWithoutARobotIsAnInputError) {
  const CliRun r =
      run_cli({"serve", source_path("scenes/foam_bar_clamped.json").string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("foam_bar_clamped.json: robot: missing"), std::string::npos) << r.err;
}

TEST(ServeCli, HostMustBeAnAddress) {
  const CliRun r = run_cli({"serve", "--host", "not-an-address", "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--host: expected an IP address, got not-an-address"), std::string::npos)
      << r.err;
}

TEST(ServeCli, WebRootNeedsAnIndexPage) {
  TempDir dir;
  const CliRun r = run_cli({"serve", "--web-root", dir.path().string(), "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--web-root: expected a directory with index.html"), std::string::npos)
      << r.err;
}

TEST(ServeCli, UnknownRobotLinkIsRefused) {
  const CliRun r = run_cli({"serve", "--robot", "warp", "--port", "0"});
  EXPECT_EQ(r.exit_code, 1);
}

}  // namespace
}  // namespace shapectl::test
