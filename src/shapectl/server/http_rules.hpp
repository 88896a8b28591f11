#pragma once
// The server's decisions about HTTP requests, kept free of networking so they are easy to test:
// which file a URL names, its content type, and which Host/Origin headers are accepted.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace shapectl::server {

// The file under `web_root` that `target` ("/js/app.js?x=1") names; "/" is "/index.html".
// nullopt for anything that could escape the root or reach hidden files: "..", "\", "%",
// control characters, segments starting with '.', or a path that is not a regular file
// inside the root once symlinks are resolved.
std::optional<std::filesystem::path> resolve_static_file(const std::filesystem::path& web_root,
                                                         std::string_view target);

// A robot mesh the page asks for: "/robot-mesh/<n>.<ext>" (an optional "?..." ignored) gives the
// table index n and ext ("stl"); nullopt for anything else. No path ever comes from the request:
// the session maps n to a file the URDF named (Session::robot_mesh_file).
inline constexpr std::string_view robot_mesh_prefix = "/robot-mesh/";
struct RobotMeshRequest {
  std::size_t index = 0;
  std::string extension;
};
std::optional<RobotMeshRequest> parse_robot_mesh_target(std::string_view target);

// "text/javascript; charset=utf-8" for .js, model/stl for .stl, and so on;
// application/octet-stream when unknown.
std::string content_type(const std::filesystem::path& file);

// DNS rebinding guard: the Host header must name a loopback or literal IP address, or the
// host the server was told to bind to (`bind_host`). Port is ignored.
bool host_allowed(std::string_view host_header, std::string_view bind_host);

// Cross-site guard for the WebSocket: a browser's Origin must be the page's own
// ("http://" + Host). Programs that send no Origin are allowed.
bool origin_allowed(std::string_view origin_header, std::string_view host_header);

}  // namespace shapectl::server
