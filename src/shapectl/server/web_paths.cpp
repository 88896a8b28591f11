#include <shapectl/server/web_paths.hpp>

#include <system_error>

namespace shapectl::server {

std::filesystem::path default_web_root() {
  const std::filesystem::path source_web = std::filesystem::path(SHAPECTL_SOURCE_DIR) / "web";
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path bin = exe.parent_path();
    // Installed (P/bin/shapectl → P/share/shapectl/web), the build tree, a nested build tree.
    for (const auto& candidate :
         {bin.parent_path() / "share" / "shapectl" / "web", bin.parent_path() / "web",
          bin.parent_path().parent_path() / "web"})
      if (std::filesystem::is_regular_file(candidate / "index.html", ec)) return candidate;
  }
  return source_web;
}

std::filesystem::path default_scenes_dir() { return default_web_root().parent_path() / "scenes"; }

}  // namespace shapectl::server
