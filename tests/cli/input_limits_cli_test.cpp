// Hostile input files end in exit 1 with a message naming the file, never a crash or a hang.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

const std::string kBar = test::source_path("scenes/yumi_bar.json").string();

std::string deep_json(const std::string& key) {
  return "{\"" + key + "\": " + std::string(55'000, '[') + std::string(55'000, ']') + "}";
}

void expect_bad_input(const std::vector<std::string>& args, const std::string& message) {
  const auto run = run_cli(args);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find(message), std::string::npos)
      << "stderr: " << run.err << "\nexpected: " << message;
}

TEST(InputLimitsCli, DeeplyNestedSceneTargetsAndJointsExitOne) {
  const TempDir dir;
  const std::string out = (dir.path() / "r.json").string();
  const auto scene = dir.write("scene.json", deep_json("object"));
  expect_bad_input({"statics", scene.string(), "--out", out},
                   scene.string() + ":1: JSON nested deeper than 64 levels");
  const auto joints = dir.write("joints.json", deep_json("joints"));
  expect_bad_input({"statics", kBar, "--joints", joints.string(), "--out", out},
                   joints.string() + ":1: JSON nested deeper than 64 levels");
  const auto targets = dir.write("targets.json", deep_json("targets"));
  expect_bad_input({"solve", kBar, "--targets", targets.string(), "--out", out},
                   targets.string() + ":1: JSON nested deeper than 64 levels");
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(InputLimitsCli, FifoSceneExitsOneWithoutWaiting) {
  const TempDir dir;
  const auto fifo = dir.path() / "scene.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  expect_bad_input({"statics", fifo.string(), "--out", (dir.path() / "r.json").string()},
                   fifo.string() + ": not a regular file (a FIFO)");
}

TEST(InputLimitsCli, DuplicateKeyInJointsExitsOne) {
  const TempDir dir;
  const auto joints =
      dir.write("joints.json", R"({"joints": {"yumi_joint_1_l": 0.1, "yumi_joint_1_l": 0.2}})");
  expect_bad_input({"statics", kBar, "--joints", joints.string(), "--out",
                    (dir.path() / "r.json").string()},
                   joints.string() + ": joints.yumi_joint_1_l: duplicate key");
}

}  // namespace
}  // namespace shapectl
