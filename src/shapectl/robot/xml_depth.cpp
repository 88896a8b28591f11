#include <shapectl/robot/xml_depth.hpp>

#include <string>

namespace shapectl {

std::size_t xml_too_deep_at(std::string_view xml, int max_depth) {
  int depth = 0;
  auto skip_past = [&](std::size_t from, std::string_view end) {
    const std::size_t at = xml.find(end, from);
    return at == std::string_view::npos ? xml.size() : at + end.size();
  };
  for (std::size_t i = xml.find('<'); i < xml.size(); i = xml.find('<', i)) {
    const std::string_view rest = xml.substr(i);
    if (rest.starts_with("<!--")) {
      i = skip_past(i + 4, "-->");
      continue;
    }
    if (rest.starts_with("<![CDATA[")) {
      i = skip_past(i + 9, "]]>");
      continue;
    }
    if (rest.starts_with("<?")) {
      i = skip_past(i + 2, "?>");
      continue;
    }
    if (rest.starts_with("<!")) {
      i = skip_past(i + 2, ">");
      continue;
    }
    if (rest.starts_with("</")) {
      --depth;
      i = skip_past(i + 2, ">");
      continue;
    }
    // An opening tag: find its end outside quoted attribute values.
    char quote = 0;
    std::size_t j = i + 1;
    for (; j < xml.size(); ++j) {
      const char c = xml[j];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') quote = c;
      else if (c == '>') break;
    }
    if (j >= xml.size()) return std::string_view::npos;  // unterminated: TinyXML reports it
    if (xml[j - 1] != '/' && ++depth > max_depth) return i;
    i = j + 1;
  }
  return std::string_view::npos;
}

}  // namespace shapectl
