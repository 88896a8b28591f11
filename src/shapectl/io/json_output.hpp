#pragma once
// Result files as JSON: pretty-printed, written atomically (io/atomic_file.hpp), never with an
// exception for text that is not valid UTF-8 (such bytes become U+FFFD).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace shapectl {

// Indented like dump(1), but arrays of numbers stay on one line ([x, y, z]). Strings that are
// not valid UTF-8 are repaired (U+FFFD), not refused: names in results come from input files.
std::string to_pretty_json(const nlohmann::json& value);
std::string to_pretty_json(const nlohmann::ordered_json& value);
void write_json_file(const std::filesystem::path& file, const nlohmann::json& value);
void write_json_file(const std::filesystem::path& file, const nlohmann::ordered_json& value);

// Where the first NaN or infinite number is ("positions[3][1]"), if any: JSON has no such
// numbers (they would be written as null), so results are checked before they are written.
std::optional<std::string> first_non_finite(const nlohmann::json& value);
std::optional<std::string> first_non_finite(const nlohmann::ordered_json& value);

}  // namespace shapectl
