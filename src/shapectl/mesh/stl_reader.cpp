#include <shapectl/mesh/stl_reader.hpp>

#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/surface_builder.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

namespace {

// ASCII STL: "solid", then facets of "outer loop", three "vertex x y z", "endloop", "endfacet".
TriangleSurface read_ascii_stl(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  SurfaceBuilder builder(name);
  std::vector<int> corners;
  bool in_facet = false;
  while (in.next()) {
    const std::string_view word = in[0];
    if (word == "facet") {
      if (in_facet) in.fail("", "'facet' before 'endfacet'");
      in_facet = true;
      corners.clear();
    } else if (word == "vertex") {
      if (!in_facet) in.fail("", "'vertex' outside a facet");
      if (in.size() != 4) in.fail("", "expected 'vertex x y z'");
      builder.add_vertex(in.point(1, "vertex"));
      corners.push_back(builder.vertex_count() - 1);
    } else if (word == "endfacet") {
      if (!in_facet) in.fail("", "'endfacet' without 'facet'");
      if (corners.size() != 3)
        in.fail("facet", "expected 3 vertices, found " + std::to_string(corners.size()));
      if (!builder.add_polygon(corners)) in.fail("facet", "uses the same vertex twice");
      in_facet = false;
    } else if (word != "solid" && word != "endsolid" && word != "outer" && word != "endloop") {
      in.fail("", "expected an STL keyword (facet, vertex, endfacet, ...), found '" + shown(word) +
                      "'");
    }
  }
  if (in_facet) in.fail("", "file ends inside a facet");
  return builder.finish(name);
}

// Binary STL: 80-byte header, uint32 count, then per triangle 12 float32 (normal, 3 vertices)
// and a uint16, little-endian.
TriangleSurface read_binary_stl(const std::string& name, const std::string& bytes) {
  auto read_float = [&](std::size_t at) {
    std::uint32_t bits = 0;
    for (int b = 3; b >= 0; --b) bits = (bits << 8) | static_cast<unsigned char>(bytes[at + b]);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return static_cast<double>(value);
  };
  const std::size_t count = (bytes.size() - 84) / 50;
  if (count > static_cast<std::size_t>(max_surface_triangles))
    throw InputError(name, "",
                     std::to_string(count) + " triangles, more than the limit of " +
                         std::to_string(max_surface_triangles) + " for a surface");
  SurfaceBuilder builder(name);
  for (std::size_t t = 0; t < count; ++t) {
    std::vector<int> corners;
    for (int c = 0; c < 3; ++c) {
      const std::size_t at = 84 + 50 * t + 12 + 12 * c;
      const Vec3 x(read_float(at), read_float(at + 4), read_float(at + 8));
      if (!x.allFinite())
        throw InputError(name, "triangle " + std::to_string(t), "vertex is not finite");
      builder.add_vertex(x);
      corners.push_back(builder.vertex_count() - 1);
    }
    if (!builder.add_polygon(corners))
      throw InputError(name, "triangle " + std::to_string(t), "uses the same vertex twice");
  }
  return builder.finish(name);
}

}  // namespace

// A binary STL is exactly 84 + 50 n bytes for the n its header states; ASCII starts "solid".
TriangleSurface read_stl(const std::string& name, const std::string& bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    for (int b = 3; b >= 0; --b) count = (count << 8) | static_cast<unsigned char>(bytes[80 + b]);
    if (bytes.size() == 84 + 50 * std::uint64_t(count)) return read_binary_stl(name, bytes);
  }
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && bytes.compare(start, 5, "solid") == 0)
    return read_ascii_stl(name, bytes);
  throw InputError(name, "",
                   "neither ASCII STL (starting with 'solid') nor binary STL (84 + 50 bytes per "
                   "triangle; this file has " +
                       std::to_string(bytes.size()) + " bytes)");
}

}  // namespace shapectl
