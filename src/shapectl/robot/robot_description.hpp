#pragma once
// The URDF text of a robot description file: ROBOT.urdf as it is, ROBOT.urdf.xacro (any name
// ending in .xacro) expanded first. Every reader of a robot file goes through here.
#include <filesystem>
#include <string>

#include <shapectl/robot/xacro_expander.hpp>

namespace shapectl {

// Throws InputError naming the file (and file:line for xacro problems).
std::string read_robot_description(const std::filesystem::path& file,
                                   const XacroOptions& xacro = {});

}  // namespace shapectl
