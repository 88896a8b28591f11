// Mutated scene and targets files: each loads or throws InputError, never anything else.
#include <gtest/gtest.h>

#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const test::TextMutator kSceneMutator({"{",
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
                                       "1e-300",
                                       "2147483648",
                                       "\"hole\": {\"min\": [-1, -1, -1], \"max\": [1, 1, 1]}",
                                       "\"density\": 1, \"density\": 2",
                                       "\"nodes\": [0, 1, 99999]",
                                       "\"linear_solver\": \"band\"",
                                       "\"max_tet_volume\": 1e-20"});

using test::bundled_scene_text;

TEST(SceneFuzz, MutatedScenesLoadOrAreInputErrors) {
  const test::TempDir dir;
  const std::vector<std::string> seeds = {bundled_scene_text("foam_bar_clamped.json"),
                                          bundled_scene_text("foam_bar_clamped.json"),
                                          bundled_scene_text("yumi_bar.json"),
                                          bundled_scene_text("yumi_frame.json")};
  for (const auto& seed : seeds) ASSERT_NO_THROW(load_scene(dir.write("seed.json", seed)));
  const test::FuzzCounts counts =
      test::fuzz_parser(seeds, kSceneMutator, 1600, 3, [&](const std::string& text) {
        load_scene(dir.write("scene.json", text));
      });
  EXPECT_GT(counts.refused, 300);
  EXPECT_GT(counts.parsed, 30);  // scenes are checked strictly: few mutations survive
}

TEST(SceneFuzz, MutatedTargetsLoadOrAreInputErrors) {
  const std::vector<std::string> seeds = {
      R"({"targets": [{"node": 3, "position": [0.1, 0.2, 0.3]}, {"node": 7, "position": [0, 0, 1]},
                      {"node": 12, "position": [0.4, 0.0, 0.25]}]})",
      R"({"centerline": [[0, 0, 0], [0.1, 0, 0.01], [0.2, 0, 0.02], [0.3, 0.01, 0.02]]})"};
  const test::FuzzCounts counts =
      test::fuzz_parser(seeds, kSceneMutator, 3000, 4, [](const std::string& text) {
        read_targets(JsonInput(parse_json_text(text, "targets.json"), "targets.json"), 425);
      });
  EXPECT_GT(counts.refused, 500);
  EXPECT_GT(counts.parsed, 100);
}

}  // namespace
}  // namespace shapectl
