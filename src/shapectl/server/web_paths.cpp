#include <shapectl/server/web_paths.hpp>

#include <system_error>

namespace shapectl::server {

std::filesystem::path default_web_root() {
  const std::filesystem::path source_web = std::filesystem::path(SHAPECTL_SOURCE_DIR) / "web";
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const auto& candidate : {exe.parent_path().parent_path() / "web",
                                  exe.parent_path().parent_path().parent_path() / "web"})
      if (std::filesystem::is_regular_file(candidate / "index.html", ec)) return candidate;
  }
  return source_web;
}

std::filesystem::path default_scenes_dir() { return default_web_root().parent_path() / "scenes"; }

}  // namespace shapectl::server
