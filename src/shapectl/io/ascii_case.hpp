#pragma once
// ASCII lower case for names a program compares (file extensions, HTTP header names). Not
// locale-aware on purpose: ".STL" must mean ".stl" whatever the user's locale.
#include <filesystem>
#include <string>
#include <string_view>

namespace shapectl {

std::string ascii_lowercase(std::string_view text);

// A file's extension with its dot, in lower case: "mesh.STL" → ".stl"; "" without one.
std::string lowercase_extension(const std::filesystem::path& file);

}  // namespace shapectl
