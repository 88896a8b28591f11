// End-to-end fuzz of the real CLI: seeded mutations of scene, joints, targets, URDF and sphere
// files, each run over an existing --out file. Every run must exit 0, 1 or 2 (no signal, no
// internal error, no hang); exit 0 writes parseable JSON with no null or non-finite number; a
// failed run leaves the old file byte for byte (statics may, as documented, replace it with a
// complete, finite "converged": false result when Newton fails: exit 2).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

// Runs the CLI under `timeout` (a hang is a failure: exit 124); the exit code, or 128 + signal.
int run_with_timeout(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> command = {"timeout", "-s", "KILL", "20"};
  for (const auto& word : test::cli_command(args)) command.push_back(word);
  return test::wait_for_exit(test::start_process(command, log));
}

bool has_null(const nlohmann::json& v) {
  if (v.is_null()) return true;
  if (v.is_number_float() && !std::isfinite(v.get<double>())) return true;
  if (v.is_structured())
    for (const auto& e : v)
      if (has_null(e)) return true;
  return false;
}

// The YuMi bar on a coarse 8 × 2 × 2 mesh, data paths made absolute.
std::string small_yumi_scene() {
  auto json = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  json["object"]["mesh"]["box"]["cells"] = {8, 2, 2};
  return json.dump(1);
}

const test::TextMutator kMutator({"{",
                                  "[",
                                  "]",
                                  "}",
                                  ",",
                                  ":",
                                  "\"",
                                  "1e999",
                                  "-1e308",
                                  "1e-400",
                                  "1e300",
                                  "1e155",
                                  "-1e300",
                                  "-0",
                                  "0",
                                  "-1",
                                  "NaN",
                                  "null",
                                  "true",
                                  "\"x\"",
                                  "[]",
                                  "{}",
                                  "[1000, 1000, 1000]",
                                  "[0, 0, 0]",
                                  "1e-13",
                                  "2147483648",
                                  "\xff",
                                  "\xc3",
                                  "<link name=\"a\xfe\"/>",
                                  "<joint name=\"j\" type=\"floating\">",
                                  "nan"});

TEST(CliFuzz, MutatedInputsExitCleanlyAndNeverDamageAnExistingResult) {
  const test::TempDir dir;
  const std::string scene = small_yumi_scene();
  const std::string joints = R"({"joints": {"yumi_joint_1_l": -0.05, "yumi_joint_2_r": -0.12}})";
  const std::string targets =
      R"({"targets": [{"node": 3, "position": [0.39, 0.02, 0.26]}, {"node": 40, "position": [0.4, -0.1, 0.27]}]})";
  const std::string centerline =
      R"({"centerline": [[0.39, 0.16, 0.255], [0.395, 0, 0.27], [0.39, -0.16, 0.255]]})";
  const std::string urdf = test::two_arm_urdf();
  const std::string arm_joints = R"({"joints": {"l1": 0.3, "r2": -0.4}})";
  const std::string spheres =
      R"({"margin": 0.005, "spheres": {"l_link3": [{"center": [0.1, 0, 0], "radius": 0.03}],
          "r_link3": [{"center": [0.1, 0, 0], "radius": 0.03}]}})";
  const std::string previous = "{\"previous\": true}\n";
  const auto out = dir.path() / "out.json";
  const auto log = dir.path() / "log.txt";

  std::mt19937 rng(20261123);
  int exits[3] = {0, 0, 0};
  constexpr int kRuns = 480;
  for (int run = 0; run < kRuns; ++run) {
    // Which command, and which of its files is mutated (the others stay valid).
    const int kind = run % 6;
    auto file = [&](const std::string& name, const std::string& text, bool mutate) {
      return dir.write(name, mutate ? kMutator.mutate(text, rng) : text).string();
    };
    const int target = static_cast<int>(rng() % 2);
    std::vector<std::string> args;
    std::string command;
    if (kind <= 1) {
      command = "statics";
      args = {"statics", file("scene.json", scene, target == 0), "--joints",
              file("joints.json", joints, target == 1)};
    } else if (kind <= 3) {
      command = "solve";
      const int which = static_cast<int>(rng() % 3);
      args = {"solve",
              file("scene.json", scene, which == 0),
              "--targets",
              file("targets.json", kind == 2 ? targets : centerline, which != 0),
              "--max-iterations",
              "2",
              "--max-seconds",
              "2",
              "--optimizer",
              run % 4 < 2 ? "gauss-newton" : "lbfgs"};
    } else {
      command = "kinematics";
      const int which = static_cast<int>(rng() % 3);
      args = {"kinematics", file("arm.urdf", urdf, which == 0),
              "--joints",   file("arm_joints.json", arm_joints, which == 1),
              "--spheres",  file("spheres.json", spheres, which == 2)};
    }
    args.insert(args.end(), {"--out", out.string()});
    dir.write("out.json", previous);
    const int code = run_with_timeout(args, log);
    const std::string what = "run " + std::to_string(run) + " (" + command + "): exit " +
                             std::to_string(code) + "\n" + test::read_text(log).substr(0, 600);
    ASSERT_TRUE(code == 0 || code == 1 || code == 2) << what;
    ++exits[code];
    const std::string written = test::read_text(out);
    if (code == 0 || (code == 2 && command == "statics" && written != previous)) {
      nlohmann::json json;
      ASSERT_NO_THROW(json = nlohmann::json::parse(written)) << what;
      EXPECT_FALSE(has_null(json)) << what;
      if (code == 2) {
        EXPECT_FALSE(json["converged"].get<bool>()) << what;
      }
    } else {
      EXPECT_EQ(written, previous) << what;
    }
    for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
      EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << what;
  }
  // The mutations reach both the parsers and the computations behind them (most are refused:
  // the formats are checked strictly).
  std::cout << "exit 0: " << exits[0] << ", exit 1: " << exits[1] << ", exit 2: " << exits[2]
            << "\n";
  EXPECT_GE(exits[0], kRuns / 40);
  EXPECT_GT(exits[1], kRuns / 4);
}

}  // namespace
}  // namespace shapectl
