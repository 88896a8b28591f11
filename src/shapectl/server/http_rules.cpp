#include <shapectl/server/http_rules.hpp>

#include <algorithm>
#include <cctype>

namespace shapectl::server {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// "host:port" or "[v6]:port" without the port; empty when malformed.
std::string host_name(std::string_view host_header) {
  if (host_header.starts_with('[')) {
    const auto close = host_header.find(']');
    if (close == std::string_view::npos) return "";
    return lower(host_header.substr(0, close + 1));
  }
  return lower(host_header.substr(0, host_header.find(':')));
}

bool is_ipv4_literal(std::string_view h) {
  int dots = 0;
  for (char c : h) {
    if (c == '.') ++dots;
    else if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  return dots == 3 && !h.empty();
}

}  // namespace

std::optional<std::filesystem::path> resolve_static_file(const std::filesystem::path& web_root,
                                                         std::string_view target) {
  std::string_view path = target.substr(0, target.find_first_of("?#"));
  if (!path.starts_with('/')) return std::nullopt;
  for (char c : path)
    if (c == '\\' || c == '%' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return std::nullopt;
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
  const auto [root_end, file_it] = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  if (root_end != root.end()) return std::nullopt;
  return file;
}

std::string content_type(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".md" || ext == ".txt") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

bool host_allowed(std::string_view host_header, std::string_view bind_host) {
  const std::string h = host_name(host_header);
  if (h.empty()) return false;
  if (h == "localhost" || h.starts_with('[') || is_ipv4_literal(h)) return true;
  return h == lower(bind_host);
}

bool origin_allowed(std::string_view origin_header, std::string_view host_header) {
  if (origin_header.empty()) return true;
  return lower(origin_header) == "http://" + lower(host_header);
}

}  // namespace shapectl::server
