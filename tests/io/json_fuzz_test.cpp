// Mutated JSON through parse_json_text and the JsonInput accessors: parse or InputError.
#include <shapectl/io/json_input.hpp>

#include <gtest/gtest.h>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const test::TextMutator kJsonMutator({"{",
                                      "[",
                                      "]",
                                      "}",
                                      ",",
                                      ":",
                                      "\"",
                                      "\"\\u0000\"",
                                      "\"\\ud800\"",
                                      "1e999",
                                      "-1e308",
                                      "1e-400",
                                      "NaN",
                                      "Infinity",
                                      "-0",
                                      "null",
                                      "true",
                                      "\"x\"",
                                      "[]",
                                      "{}",
                                      "99999999999999999999999",
                                      "\"density\": 1, \"density\": 2",
                                      "\xff\xfe",
                                      "\"\xc3\""});

// Walks any JSON value the way the readers do: typed accessors that must throw InputError
// for the wrong type or a non-finite number, never anything else.
void read_everything(const JsonInput& j, int depth = 0) {
  if (depth > 70) return;
  try {
    j.number();
  } catch (const InputError&) {
  }
  try {
    j.integer_in(-5, 5);
  } catch (const InputError&) {
  }
  try {
    j.string();
  } catch (const InputError&) {
  }
  try {
    j.vec3();
  } catch (const InputError&) {
  }
  try {
    j.boolean();
  } catch (const InputError&) {
  }
  try {
    j.expect_only({"a"});
  } catch (const InputError&) {
  }
  if (j.is_object())
    for (const auto& key : j.keys()) read_everything(j.at(key), depth + 1);
  if (j.is_array())
    for (std::size_t k = 0; k < j.size() && k < 50; ++k) read_everything(j.at(k), depth + 1);
}

TEST(JsonFuzz, MutatedScenesAndTargetsParseOrAreInputErrors) {
  const std::vector<std::string> seeds = {
      test::read_text(test::source_path("scenes/foam_bar_clamped.json")),
      test::read_text(test::source_path("scenes/yumi_bar.json")),
      test::read_text(test::source_path("data/robots/yumi/yumi_spheres.json")),
      R"({"targets": [{"node": 3, "position": [0.1, 0.2, 0.3]}, {"node": 7, "position": [0, 0, 1]}]})",
      R"({"centerline": [[0, 0, 0], [0.1, 0, 0.01], [0.2, 0, 0.02]]})",
      R"({"joints": {"yumi_joint_1_l": -0.1, "yumi_joint_2_l": 0.5}})"};
  const test::FuzzCounts counts =
      test::fuzz_parser(seeds, kJsonMutator, 4000, 20261123, [](const std::string& text) {
        read_everything(JsonInput(parse_json_text(text, "fuzz.json"), "fuzz.json"));
      });
  // Both outcomes occur: the mutations reach the parser and the accessors behind it.
  EXPECT_GT(counts.refused, 400);
  EXPECT_GT(counts.parsed, 200);
}

}  // namespace
}  // namespace shapectl
