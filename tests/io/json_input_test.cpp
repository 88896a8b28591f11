// Strict JSON input: bounded size and depth, no duplicate keys, bounded messages, and files
// that are not regular (a FIFO, a directory) refused without waiting.
#include <shapectl/io/json_input.hpp>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <shapectl/io/input_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::TempDir;

std::string error_of(const std::function<void()>& f) { return test::input_error_of(f); }

std::string nested(int depth) {
  return std::string(static_cast<std::size_t>(depth), '[') +
         std::string(static_cast<std::size_t>(depth), ']');
}

TEST(JsonInput, DeeplyNestedTextIsRefusedBeforeParsing) {
  const std::string deep = "{\"object\": " + nested(55'000) + "}";
  EXPECT_EQ(error_of([&] { parse_json_text(deep, "scene.json"); }),
            "scene.json:1: JSON nested deeper than 64 levels");
  // Brackets inside strings do not count; 64 levels are fine.
  EXPECT_NO_THROW(parse_json_text("{\"a\": \"" + std::string(1000, '[') + "\"}", "s.json"));
  EXPECT_NO_THROW(parse_json_text(nested(64), "s.json"));
  EXPECT_NE(error_of([&] { parse_json_text(nested(65), "s.json"); }), "");
}

TEST(JsonInput, DeeplyNestedFileIsAnInputErrorNamingIt) {
  const TempDir dir;
  const auto file = dir.write("deep.json", "{\n\"targets\": " + nested(55'000) + "}");
  EXPECT_EQ(error_of([&] { JsonInput::load(file); }),
            file.string() + ":2: JSON nested deeper than 64 levels");
}

TEST(JsonInput, DuplicateKeysAreErrorsNamingPathAndKey) {
  EXPECT_EQ(error_of([] {
              parse_json_text(R"({"object": {"material": {"density": 40, "density": 4}}})",
                              "s.json");
            }),
            "s.json: object.material.density: duplicate key (each key may appear once)");
  EXPECT_EQ(error_of([] {
              parse_json_text(R"({"grips": [{"a": 1}, {"b": [1, {"c": 1, "c": 2}]}]})", "s.json");
            }),
            "s.json: grips[1].b[1].c: duplicate key (each key may appear once)");
  // The same key in different objects is fine.
  EXPECT_NO_THROW(
      parse_json_text(R"({"a": {"x": 1}, "b": {"x": 1}, "c": [{"x": 1}, {"x": 2}]})", "s.json"));
}

TEST(JsonInput, NumbersBeyondADoubleAreErrorsNamingTheirPath) {
  // Read as a double they would be infinite: refused while parsing, named where they stand.
  for (const auto& [text, where] : std::vector<std::pair<std::string, std::string>>{
           {R"({"loads": [{"force": [0, 0, -1e999]}]})", "loads[0].force[2]"},
           {R"({"loads": [{"nodes": [1]}, {"force": [1e400, 0, 0]}]})", "loads[1].force[0]"},
           {R"({"gravity": 1e999})", "gravity"},
           {R"([{"a": 1}, 2, -1e999])", "[2]"}}) {
    const std::string message = error_of([&] { parse_json_text(text, "s.json"); });
    EXPECT_EQ(message.rfind("s.json: " + where + ": expected a finite number, got one out of range",
                            0),
              0u)
        << message;
  }
}

TEST(JsonInput, HugeUnknownKeyIsEchoedBounded) {
  const std::string key(5'000'000, 'k');
  const JsonInput json(parse_json_text("{\"" + key + "\": 1}", "s.json"), "s.json");
  const std::string message = error_of([&] { json.expect_only({"object"}); });
  EXPECT_EQ(message, "s.json: " + std::string(80, 'k') + "…: unknown key; known: object");
}

TEST(JsonInput, HugeValueIsShownBounded) {
  const JsonInput json(parse_json_text("{\"a\": [\"" + std::string(5'000'000, 'v') + "\", 1]}",
                                       "s.json"),
                       "s.json");
  const std::string message = error_of([&] { json.at("a").number(); });
  EXPECT_EQ(message.rfind("s.json: a: expected a number, got [\"vvv", 0), 0u)
      << message.substr(0, 200);
  EXPECT_LT(message.size(), 120u);
}

TEST(JsonInput, ParseErrorWithHugeTokenIsBounded) {
  const std::string message =
      error_of([] { parse_json_text("[\"" + std::string(3'000'000, 'x'), "s.json"); });
  EXPECT_EQ(message.rfind("s.json:1: invalid JSON (", 0), 0u) << message.substr(0, 200);
  EXPECT_LT(message.size(), 300u);
}

TEST(JsonInput, OversizeTextAndFilesAreRefusedNamingTheLimit) {
  EXPECT_EQ(error_of([] { parse_json_text("[1, 2, 3]", "m", {.max_bytes = 4}); }),
            "m: longer than the 4 byte limit for JSON");
  const TempDir dir;
  const auto file = dir.write("targets.json", "[" + std::string(max_json_file_bytes, ' ') + "]");
  EXPECT_EQ(error_of([&] { JsonInput::load(file); }),
            file.string() + ": larger than the " + std::to_string(max_json_file_bytes) +
                " byte limit for JSON files (" + std::to_string(max_json_file_bytes + 2) +
                " bytes)");
}

TEST(InputFile, FifoIsRefusedWithoutWaitingForAWriter) {
  const TempDir dir;
  const auto fifo = dir.path() / "scene.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { JsonInput::load(fifo); }),
            fifo.string() + ": not a regular file (a FIFO)");
  EXPECT_EQ(error_of([&] { read_input_file(dir.path(), 100, "mesh"); }),
            dir.path().string() + ": not a regular file (a directory)");
  EXPECT_EQ(error_of([&] { read_input_file("/dev/zero", 100, "mesh"); }),
            "/dev/zero: not a regular file (a character device)");
  EXPECT_EQ(error_of([&] { read_input_file(dir.path() / "none.json", 100, "JSON"); }),
            (dir.path() / "none.json").string() + ": cannot open file (No such file or directory)");
}

TEST(InputFile, ReadsARegularFileUpToTheLimit) {
  const TempDir dir;
  const auto file = dir.write("a.txt", "12345");
  EXPECT_EQ(read_input_file(file, 5, "text"), "12345");
  EXPECT_EQ(error_of([&] { read_input_file(file, 4, "text"); }),
            file.string() + ": larger than the 4 byte limit for text files (5 bytes)");
}

TEST(BoundedPreview, CutsAtACharacterBoundaryAndHidesControlCharacters) {
  EXPECT_EQ(bounded_preview("short"), "short");
  EXPECT_EQ(bounded_preview("a\nb\x1b"), "a?b?");
  EXPECT_EQ(bounded_preview("abcdef", 3), "abc…");
  EXPECT_EQ(bounded_preview("ab\xc3\xa9z", 3), "ab…");  // é is two bytes: not split
}

TEST(JsonInput, NumberRangesNameTheRange) {
  const JsonInput json(parse_json_text(R"({"g": [0, 0, -1e300], "e": 1e20})", "s.json"), "s.json");
  EXPECT_EQ(error_of([&] { json.at("g").vec3_within(1e3, "a gravity vector", "m/s^2"); }),
            "s.json: g: expected a gravity vector of length at most 1000 m/s^2, got [0,0,-1e+300]");
  EXPECT_EQ(error_of([&] { json.at("e").number_in(1, 1e13, "Pa"); }),
            "s.json: e: expected a number from 1 to 1e+13 Pa, got 1e+20");
}

}  // namespace
}  // namespace shapectl
