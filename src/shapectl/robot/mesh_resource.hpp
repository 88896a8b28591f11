#pragma once
// URDF mesh file names resolved the way ROS does: relative to the URDF, file://, and
// package:// through package paths (--package-path, $ROS_PACKAGE_PATH).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace shapectl {

// The file a URDF mesh name refers to, if it exists: "package://pkg/rest" is searched as
// <dir>/pkg/rest for each package path, and as <dir>/rest when <dir> is the package pkg itself
// (named pkg, or its package.xml says <name>pkg</name>); "file:///abs" is taken as is; a plain
// name is relative to the URDF's directory.
std::optional<std::filesystem::path> resolve_mesh_file(
    const std::string& filename, const std::filesystem::path& urdf_directory,
    const std::vector<std::filesystem::path>& package_paths);

// The folder of ROS package `package` ($(find package) in xacro): for each dir of package_paths,
// dir itself when it is that package (named so, or so declared in its package.xml), else
// dir/package when that is a folder.
std::optional<std::filesystem::path> find_ros_package(
    const std::string& package, const std::vector<std::filesystem::path>& package_paths);

// `given` followed by the entries of $ROS_PACKAGE_PATH (colon-separated, empty ones skipped).
std::vector<std::filesystem::path> with_ros_package_path(std::vector<std::filesystem::path> given);

}  // namespace shapectl
