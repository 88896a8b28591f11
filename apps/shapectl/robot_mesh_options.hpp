#pragma once
// `--package-path DIR` (repeatable) for every command that loads a robot, and the notes each
// prints about it: the URDF's skipped geometry and every visual mesh that cannot be drawn.
// `--xacro-arg NAME:=VALUE` for commands that take a ROBOT.urdf.xacro.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include <shapectl/robot/visual_meshes.hpp>
#include <shapectl/robot/xacro_expander.hpp>

namespace shapectl::cli {

void add_package_path_option(CLI::App& cmd, std::vector<std::string>& package_paths);
// The --package-path folders, then $ROS_PACKAGE_PATH's.
std::vector<std::filesystem::path> package_paths(const std::vector<std::string>& given);

void add_xacro_arg_option(CLI::App& cmd, std::vector<std::string>& xacro_args);
// How a ROBOT.urdf.xacro expands: $(find) searches the --package-path folders (then
// $ROS_PACKAGE_PATH and the folders above the file); `xacro_args` are NAME:=VALUE (InputError
// naming --xacro-arg otherwise).
XacroOptions xacro_options(const std::vector<std::string>& package_paths,
                           const std::vector<std::string>& xacro_args = {});

// The model's warnings (skipped geometry) and one per visual mesh that cannot be drawn
// (visual_mesh_warning), one line each.
std::vector<std::string> robot_notes(const RobotModel& model,
                                     const std::vector<std::string>& package_paths);
// robot_notes() as "warning: ..." lines on stderr.
void print_robot_notes(const RobotModel& model, const std::vector<std::string>& package_paths);

}  // namespace shapectl::cli
