#include <shapectl/calib/ply_points.hpp>

#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

#include <shapectl/calib/little_endian.hpp>
#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

namespace {

enum class PlyType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

// Both spellings in use: the original (char, uchar, ...) and the sized one (int8, ...).
std::optional<PlyType> ply_type(std::string_view name) {
  static constexpr std::pair<std::string_view, PlyType> names[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::Uint8},
      {"uint8", PlyType::Uint8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::Uint16},  {"uint16", PlyType::Uint16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::Uint32},     {"uint32", PlyType::Uint32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& [text, type] : names)
    if (text == name) return type;
  return std::nullopt;
}

std::size_t ply_size(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::Uint8: return 1;
    case PlyType::Int16:
    case PlyType::Uint16: return 2;
    case PlyType::Int32:
    case PlyType::Uint32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 8;
}

bool is_floating(PlyType type) { return type == PlyType::Float32 || type == PlyType::Float64; }

// The value of `type` stored at `at`; every PLY type fits a double exactly.
double read_ply_binary(PlyType type, const char* at) {
  switch (type) {
    case PlyType::Int8: return read_little_endian<std::int8_t>(at);
    case PlyType::Uint8: return read_little_endian<std::uint8_t>(at);
    case PlyType::Int16: return read_little_endian<std::int16_t>(at);
    case PlyType::Uint16: return read_little_endian<std::uint16_t>(at);
    case PlyType::Int32: return read_little_endian<std::int32_t>(at);
    case PlyType::Uint32: return read_little_endian<std::uint32_t>(at);
    case PlyType::Float32: return read_little_endian<float>(at);
    case PlyType::Float64: return read_little_endian<double>(at);
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type;                       // a scalar's, or a list's items'
  std::optional<PlyType> count_type;  // a list's length; none for a scalar
  int axis = -1;                      // 0, 1, 2 for the vertex element's x, y, z
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  int line = 0;  // of its "element" line, for messages
};

struct PlyHeader {
  bool binary = false;
  std::vector<PlyElement> elements;
  std::size_t vertex = 0;  // index of the vertex element
};

// Where the data starts: after the line "end_header", which must come within the first 64 kB.
std::size_t ply_data_start(const std::string& name, const std::string& bytes) {
  constexpr std::size_t max_header_bytes = 1 << 16;
  if (!bytes.starts_with("ply\n") && !bytes.starts_with("ply\r\n"))
    throw InputError(name + ":1", "", "expected 'ply' (the PLY magic line)");
  for (std::size_t pos = 0; pos < std::min(bytes.size(), max_header_bytes);) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) break;
    std::string_view line(bytes.data() + pos, end - pos);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.remove_suffix(1);
    if (line == "end_header") return end + 1;
    pos = end + 1;
  }
  throw InputError(name, "header",
                   "no 'end_header' line in the first " + std::to_string(max_header_bytes) +
                       " bytes");
}

PlyType scalar_type(const TextLines& in, std::size_t i) {
  const auto type = ply_type(in[i]);
  if (!type)
    in.fail("property",
            "expected a PLY type (char, uchar, short, ushort, int, uint, float, "
            "double or int8 ... float64), got '" +
                shown(in[i]) + "'");
  return *type;
}

PlyProperty read_property(const TextLines& in) {
  PlyProperty p;
  if (in.size() >= 2 && in[1] == "list") {
    in.expect_values(5, "property", "property list, count type, item type, name");
    p.count_type = scalar_type(in, 2);
    if (is_floating(*p.count_type))
      in.fail("property", "expected an integer type for a list's length");
    p.type = scalar_type(in, 3);
    p.name = in[4];
  } else {
    in.expect_values(3, "property", "property, type, name");
    p.type = scalar_type(in, 1);
    p.name = in[2];
  }
  return p;
}

// The vertex element's x, y, z: present once each, floating scalars; marks their axes.
void find_coordinates(const std::string& name, PlyElement& vertex) {
  const std::string where = "element 'vertex'";
  const std::string source = name + ":" + std::to_string(vertex.line);
  if (vertex.count > max_point_cloud_points)
    throw InputError(source, where,
                     std::to_string(vertex.count) + " vertices, more than the limit of " +
                         std::to_string(max_point_cloud_points));
  for (int axis = 0; axis < 3; ++axis) {
    const std::string axis_name(1, "xyz"[axis]);
    int found = 0;
    for (PlyProperty& p : vertex.properties) {
      if (p.name != axis_name) continue;
      if (p.count_type || !is_floating(p.type))
        throw InputError(source, where,
                         "expected property " + axis_name + " of type float or double");
      p.axis = axis;
      ++found;
    }
    if (found != 1)
      throw InputError(source, where,
                       "expected one property " + axis_name + ", found " + std::to_string(found));
  }
}

// Reads the header lines from `in` (positioned at the start of the file) up to "end_header".
PlyHeader read_ply_header(const std::string& name, TextLines& in) {
  PlyHeader h;
  bool format_seen = false;
  in.next("'ply'");
  while (in.next()) {
    const std::string_view word = in[0];
    if (word == "comment" || word == "obj_info") continue;
    if (word == "end_header") {  // the line ply_data_start found: the text ends with it
      in.expect_values(1, "end_header", "end_header alone");
      break;
    }
    if (word == "format") {
      if (format_seen) in.fail("format", "given twice");
      in.expect_values(3, "format", "format, encoding, version");
      if (in[1] != "ascii" && in[1] != "binary_little_endian")
        in.fail("format", "expected ascii or binary_little_endian, got '" + shown(in[1]) + "'");
      if (in[2] != "1.0") in.fail("format", "expected version 1.0, got '" + shown(in[2]) + "'");
      h.binary = in[1] == "binary_little_endian";
      format_seen = true;
    } else if (word == "element") {
      if (!format_seen) in.fail("element", "expected the 'format' line before any element");
      in.expect_values(3, "element", "element, name, count");
      const auto count = static_cast<std::uint64_t>(in.count(2, "element count"));
      h.elements.push_back({std::string(in[1]), count, {}, in.line()});
    } else if (word == "property") {
      if (h.elements.empty()) in.fail("property", "expected an 'element' line before it");
      h.elements.back().properties.push_back(read_property(in));
    } else {
      in.fail("",
              "expected a PLY header keyword (format, element, property, comment, "
              "end_header), got '" +
                  shown(word) + "'");
    }
  }
  if (!format_seen) throw InputError(name, "header", "no 'format' line");
  for (const PlyElement& e : h.elements)
    if (e.properties.empty())
      throw InputError(name + ":" + std::to_string(e.line), "element '" + shown(e.name) + "'",
                       "expected at least one property");
  for (h.vertex = 0; h.vertex < h.elements.size(); ++h.vertex)
    if (h.elements[h.vertex].name == "vertex") break;
  if (h.vertex == h.elements.size()) throw InputError(name, "header", "no 'vertex' element");
  find_coordinates(name, h.elements[h.vertex]);
  return h;
}

std::string instance_name(const PlyElement& e, std::uint64_t i) {
  return shown(e.name) + " " + std::to_string(i);
}

// One element instance a line: its values in property order, a list as its length and items.
// Reads the elements up to the vertices; returns the vertices' points.
std::vector<Vec3> read_ascii_data(TextLines& in, const PlyHeader& h) {
  std::vector<Vec3> points;
  for (std::size_t e = 0; e <= h.vertex; ++e) {
    const PlyElement& element = h.elements[e];
    for (std::uint64_t i = 0; i < element.count; ++i) {
      const std::string where = instance_name(element, i);
      in.next(where);
      Vec3 point = Vec3::Zero();
      std::size_t token = 0;
      for (const PlyProperty& p : element.properties) {
        if (token >= in.size())
          in.fail(where, "expected a value for property '" + shown(p.name) + "', the line has " +
                             std::to_string(in.size()) + " values");
        if (p.count_type) {
          const long long length = in.integer(token, where, "list length");
          if (length < 0 || static_cast<std::size_t>(length) > in.size() - token - 1)
            in.fail(where, "list '" + shown(p.name) + "': length " + std::to_string(length) +
                               " does not fit the line's " + std::to_string(in.size()) + " values");
          token += 1 + static_cast<std::size_t>(length);
        } else {
          if (p.axis >= 0) point[p.axis] = in.real(token, where, p.name);
          ++token;
        }
      }
      if (token != in.size())
        in.fail(where, "expected " + std::to_string(token) + " values, found " +
                           std::to_string(in.size()));
      if (e == h.vertex) points.push_back(point);
    }
  }
  return points;
}

// Instances packed in property order; a list is its length then its items.
std::vector<Vec3> read_binary_data(const std::string& name, const std::string& bytes,
                                   std::size_t pos, const PlyHeader& h) {
  std::vector<Vec3> points;
  for (std::size_t e = 0; e <= h.vertex; ++e) {
    const PlyElement& element = h.elements[e];
    if (e == h.vertex) points.reserve(element.count);
    for (std::uint64_t i = 0; i < element.count; ++i) {
      // Every property takes at least one byte, so a huge count ends at the end of the file.
      auto take = [&](std::size_t n) {
        if (bytes.size() - pos < n)
          throw InputError(name, instance_name(element, i), "the file ends inside it (truncated)");
        const char* at = bytes.data() + pos;
        pos += n;
        return at;
      };
      Vec3 point = Vec3::Zero();
      for (const PlyProperty& p : element.properties) {
        if (p.count_type) {
          const double length = read_ply_binary(*p.count_type, take(ply_size(*p.count_type)));
          if (length < 0)
            throw InputError(name, instance_name(element, i),
                             "list '" + shown(p.name) + "': negative length");
          const std::size_t item = ply_size(p.type);
          if (length > static_cast<double>((bytes.size() - pos) / item))
            throw InputError(name, instance_name(element, i),
                             "the file ends inside it (truncated)");
          take(static_cast<std::size_t>(length) * item);
        } else {
          const char* at = take(ply_size(p.type));
          if (p.axis >= 0) point[p.axis] = read_ply_binary(p.type, at);
        }
      }
      if (e != h.vertex) continue;
      if (!point.allFinite())
        throw InputError(name, instance_name(element, i), "expected finite x, y, z");
      points.push_back(point);
    }
  }
  return points;
}

}  // namespace

std::vector<Vec3> read_ply_points(const std::string& name, std::string bytes) {
  const std::size_t data_start = ply_data_start(name, bytes);
  TextLines header_lines(name, bytes.substr(0, data_start), TextLines::Comments::None);
  const PlyHeader header = read_ply_header(name, header_lines);
  if (header.binary) return read_binary_data(name, bytes, data_start, header);
  // Ascii: read on past the header with the same line numbers.
  TextLines in(name, std::move(bytes), TextLines::Comments::None);
  while (in.line() < header_lines.line() && in.next()) {
  }
  return read_ascii_data(in, header);
}

}  // namespace shapectl
