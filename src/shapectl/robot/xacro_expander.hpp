#pragma once
// ROBOT.urdf.xacro expanded into URDF text, for the subset robot descriptions use (docs/robot.md
// "Robots described in xacro"): xacro:property, xacro:macro (parameters, defaults, ^, *blocks),
// xacro:insert_block, macro calls, xacro:include with $(find pkg), ${} expressions, $(arg),
// $(env), $(optenv), xacro:arg, xacro:if and xacro:unless.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace shapectl {

struct XacroOptions {
  // Where $(find pkg) looks, before $ROS_PACKAGE_PATH and the folders above the xacro file.
  std::vector<std::filesystem::path> package_paths;
  std::map<std::string, std::string> args;  // name:=value, overriding xacro:arg defaults
};

inline constexpr int max_xacro_include_depth = 16;
inline constexpr int max_xacro_macro_depth = 64;

// The URDF text `file` expands to. Throws InputError naming file:line and what was expected
// (an undefined property, macro or arg, a missing include, a bad expression, an unknown xacro
// tag, an include cycle, or an expansion larger than max_urdf_file_bytes).
std::string expand_xacro_file(const std::filesystem::path& file, const XacroOptions& options = {});

// Whether `file` is to be expanded: its name ends in ".xacro".
bool is_xacro_file(const std::filesystem::path& file);

}  // namespace shapectl
