#include "robot_mesh_options.hpp"

#include <iostream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/mesh_resource.hpp>

namespace shapectl::cli {

void add_package_path_option(CLI::App& cmd, std::vector<std::string>& package_paths) {
  cmd.add_option("--package-path", package_paths,
                 "Folder holding ROS packages, or a package itself, for the URDF's "
                 "package:// meshes (repeatable; $ROS_PACKAGE_PATH is searched after)");
}

std::vector<std::filesystem::path> package_paths(const std::vector<std::string>& given) {
  return with_ros_package_path({given.begin(), given.end()});
}

void add_xacro_arg_option(CLI::App& cmd, std::vector<std::string>& xacro_args) {
  cmd.add_option("--xacro-arg", xacro_args,
                 "NAME:=VALUE for $(arg NAME) of a ROBOT.urdf.xacro (repeatable; others take "
                 "their xacro:arg default)");
}

XacroOptions xacro_options(const std::vector<std::string>& given,
                           const std::vector<std::string>& xacro_args) {
  XacroOptions options;
  options.package_paths = {given.begin(), given.end()};
  for (const std::string& arg : xacro_args) {
    const auto at = arg.find(":=");
    if (at == std::string::npos || at == 0)
      throw InputError("--xacro-arg", "", "expected NAME:=VALUE", "'" + arg + "'");
    options.args[arg.substr(0, at)] = arg.substr(at + 2);
  }
  return options;
}

std::vector<std::string> robot_notes(const RobotModel& model,
                                     const std::vector<std::string>& given) {
  std::vector<std::string> notes = model.warnings();
  for (const auto& m : find_visual_meshes(model, package_paths(given)))
    if (!m.file) notes.push_back(visual_mesh_warning(model, m));
  return notes;
}

void print_robot_notes(const RobotModel& model, const std::vector<std::string>& given) {
  for (const auto& note : robot_notes(model, given)) std::cerr << "warning: " << note << "\n";
}

}  // namespace shapectl::cli
