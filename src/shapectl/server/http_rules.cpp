#include <shapectl/server/http_rules.hpp>

#include <arpa/inet.h>

#include <algorithm>

#include <shapectl/io/ascii_case.hpp>

namespace shapectl::server {

namespace {

bool all_digits(std::string_view s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

// A dotted quad, each octet 0-255 without leading zeros (which some resolvers read as octal).
bool is_ipv4_literal(std::string_view h) {
  for (int octet = 0; octet < 4; ++octet) {
    const std::size_t end = octet < 3 ? h.find('.') : h.size();
    if (end == std::string_view::npos) return false;
    const std::string_view part = h.substr(0, end);
    if (!all_digits(part) || part.size() > 3 || (part.size() > 1 && part[0] == '0')) return false;
    if (std::stoi(std::string(part)) > 255) return false;
    h = octet < 3 ? h.substr(end + 1) : std::string_view();
  }
  return true;
}

// Hex digits and colons with at most one "::", or an IPv4 tail: checked by inet_pton.
bool is_ipv6_literal(std::string_view h) {
  if (h.empty() || h.size() > 45) return false;
  in6_addr address{};
  return inet_pton(AF_INET6, std::string(h).c_str(), &address) == 1;
}

// RFC 1123 labels; a name whose last label is numeric would be an IPv4 address, not a name.
bool is_hostname(std::string_view h) {
  if (h.empty() || h.size() > 253 || h.back() == '.') return false;
  std::string_view last;
  while (!h.empty()) {
    const std::size_t end = std::min(h.find('.'), h.size());
    const std::string_view label = h.substr(0, end);
    if (label.empty() || label.size() > 63 || label.front() == '-' || label.back() == '-')
      return false;
    for (unsigned char c : label)
      if (!std::isalnum(c) && c != '-') return false;
    last = label;
    h = end < h.size() ? h.substr(end + 1) : std::string_view();
  }
  return !all_digits(last);
}

// The host part of a Host header ("name", "1.2.3.4" or "[v6]", lower case) if the header is
// well formed with an optional port 1-65535; empty otherwise.
std::string host_name(std::string_view header) {
  std::string_view host = header, port;
  if (header.starts_with('[')) {
    const auto close = header.find(']');
    if (close == std::string_view::npos || !is_ipv6_literal(header.substr(1, close - 1))) return "";
    host = header.substr(0, close + 1);
    const std::string_view rest = header.substr(close + 1);
    if (!rest.empty() && !rest.starts_with(':')) return "";
    if (!rest.empty()) port = rest.substr(1);
    if (rest == ":") return "";
  } else if (const auto colon = header.find(':'); colon != std::string_view::npos) {
    host = header.substr(0, colon);
    port = header.substr(colon + 1);
    if (port.empty()) return "";
  }
  if (!port.empty() && (!all_digits(port) || port.size() > 5 || std::stoi(std::string(port)) < 1 ||
                        std::stoi(std::string(port)) > 65535))
    return "";
  const std::string h = ascii_lowercase(host);
  if (h.starts_with('[') || is_ipv4_literal(h) || is_hostname(h)) return h;
  return "";
}

}  // namespace

std::optional<std::filesystem::path> resolve_static_file(const std::filesystem::path& web_root,
                                                         std::string_view target) {
  std::string_view path = target.substr(0, target.find_first_of("?#"));
  if (!path.starts_with('/')) return std::nullopt;
  for (char c : path)
    if (c == '\\' || c == '%' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      return std::nullopt;
  std::string relative = path == "/" ? "index.html" : std::string(path.substr(1));
  // Every segment must be a plain name: no "", ".", "..", or hidden files.
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t end = std::min(relative.find('/', start), relative.size());
    const std::string_view segment = std::string_view(relative).substr(start, end - start);
    if (segment.empty() || segment.starts_with('.')) return std::nullopt;
    start = end + 1;
  }
  std::error_code ec;
  const auto root = std::filesystem::canonical(web_root, ec);
  if (ec) return std::nullopt;
  const auto file = std::filesystem::canonical(root / relative, ec);
  if (ec || !std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  // Symlinks must not lead out of the root.
  const auto [root_end, file_it] =
      std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  if (root_end != root.end()) return std::nullopt;
  return file;
}

std::optional<RobotMeshRequest> parse_robot_mesh_target(std::string_view target) {
  std::string_view path = target.substr(0, target.find('?'));
  if (!path.starts_with(robot_mesh_prefix)) return std::nullopt;
  path.remove_prefix(robot_mesh_prefix.size());
  const std::size_t dot = path.find('.');
  if (dot == std::string_view::npos) return std::nullopt;
  const std::string_view number = path.substr(0, dot), extension = path.substr(dot + 1);
  if (!all_digits(number) || number.size() > 6 || (number.size() > 1 && number[0] == '0'))
    return std::nullopt;
  if (extension != "stl" && extension != "obj" && extension != "dae") return std::nullopt;
  return RobotMeshRequest{static_cast<std::size_t>(std::stoul(std::string(number))),
                          std::string(extension)};
}

std::string content_type(const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".md" || ext == ".txt") return "text/plain; charset=utf-8";
  if (ext == ".stl") return "model/stl";
  if (ext == ".obj") return "model/obj";
  if (ext == ".dae") return "model/vnd.collada+xml";
  return "application/octet-stream";
}

bool host_allowed(std::string_view host_header, std::string_view bind_host) {
  const std::string h = host_name(host_header);
  if (h.empty()) return false;
  if (h == "localhost" || h.starts_with('[') || is_ipv4_literal(h)) return true;
  return h == ascii_lowercase(bind_host);
}

bool origin_allowed(std::string_view origin_header, std::string_view host_header) {
  if (origin_header.empty()) return true;
  return ascii_lowercase(origin_header) == "http://" + ascii_lowercase(host_header);
}

}  // namespace shapectl::server
