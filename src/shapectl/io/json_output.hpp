#pragma once
// Writing result files: atomically (a temporary file beside the target, then a rename), so a
// failure never leaves a half-written or corrupted file where a good one was.
#include <filesystem>
#include <nlohmann/json.hpp>

#include <shapectl/types.hpp>

namespace shapectl {

// Throws InputError naming the path if it cannot be written (e.g. missing directory).
void write_text_file_atomically(const std::filesystem::path& file, const std::string& text);
std::string to_pretty_json(const nlohmann::json& value);
void write_json_file(const std::filesystem::path& file, const nlohmann::json& value);

// [[x,y,z], ...] from stacked positions.
nlohmann::json positions_to_json(const Positions& x);

}  // namespace shapectl
