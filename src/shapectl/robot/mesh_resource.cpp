#include <shapectl/robot/mesh_resource.hpp>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

namespace shapectl {

namespace {

bool is_existing_file(const std::filesystem::path& p) {
  std::error_code error;
  return std::filesystem::is_regular_file(p, error);
}

// Whether `dir` is the ROS package `package`: so named, or so declared in its package.xml.
bool is_package_dir(const std::filesystem::path& dir, const std::string& package) {
  if (dir.filename() == package ||
      (dir.filename().empty() && dir.parent_path().filename() == package))
    return true;
  std::ifstream in(dir / "package.xml");
  if (!in) return false;
  std::string head(4096, '\0');  // the name comes first; no need to read a large file
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::smatch match;
  return std::regex_search(head, match, std::regex(R"(<name>\s*([^<\s]+)\s*</name>)")) &&
         match[1] == package;
}

}  // namespace

std::optional<std::filesystem::path> resolve_mesh_file(
    const std::string& filename, const std::filesystem::path& urdf_directory,
    const std::vector<std::filesystem::path>& package_paths) {
  const std::string package_scheme = "package://", file_scheme = "file://";
  if (filename.rfind(package_scheme, 0) == 0) {
    const std::string rest = filename.substr(package_scheme.size());
    const auto slash = rest.find('/');
    if (slash == std::string::npos || slash == 0) return std::nullopt;
    const std::string package = rest.substr(0, slash);
    const std::filesystem::path within = rest.substr(slash + 1);
    for (const auto& dir : package_paths) {
      if (is_existing_file(dir / rest)) return dir / rest;
      if (is_existing_file(dir / within) && is_package_dir(dir, package)) return dir / within;
    }
    return std::nullopt;
  }
  std::filesystem::path path =
      filename.rfind(file_scheme, 0) == 0 ? filename.substr(file_scheme.size()) : filename;
  if (path.is_relative()) path = urdf_directory / path;
  if (is_existing_file(path)) return path;
  return std::nullopt;
}

std::optional<std::filesystem::path> find_ros_package(
    const std::string& package, const std::vector<std::filesystem::path>& package_paths) {
  std::error_code error;
  for (const auto& dir : package_paths) {
    if (std::filesystem::is_directory(dir, error) && is_package_dir(dir, package)) return dir;
    if (std::filesystem::is_directory(dir / package, error)) return dir / package;
  }
  return std::nullopt;
}

std::vector<std::filesystem::path> with_ros_package_path(std::vector<std::filesystem::path> given) {
  if (const char* env = std::getenv("ROS_PACKAGE_PATH")) {
    std::istringstream entries(env);
    for (std::string entry; std::getline(entries, entry, ':');)
      if (!entry.empty()) given.emplace_back(entry);
  }
  return given;
}

}  // namespace shapectl
