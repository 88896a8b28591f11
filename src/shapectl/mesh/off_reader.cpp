#include <shapectl/mesh/off_reader.hpp>

#include <vector>

#include <shapectl/mesh/surface_builder.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

TriangleSurface read_off(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  in.next("the OFF header");
  if (in[0].size() < 3 || !in[0].ends_with("OFF"))
    in.fail("", "expected the OFF header, found '" + shown(in[0]) + "'");
  std::size_t first = 1;  // the counts may follow the header on the same line
  if (in.size() == 1) {
    in.next("the counts 'vertices faces edges'");
    first = 0;
  }
  if (in.size() < first + 2) in.fail("", "expected the counts 'vertices faces edges'");
  const long long vertices = in.count(first, "vertex count");
  const long long faces = in.count(first + 1, "face count");
  SurfaceBuilder builder(name);
  for (long long v = 0; v < vertices; ++v) {
    const std::string where = "vertex " + std::to_string(v);
    in.next(where + " of " + std::to_string(vertices));
    if (in.size() < 3) in.fail(where, "expected 'x y z'");
    builder.add_vertex(in.point(0, where));
  }
  for (long long f = 0; f < faces; ++f) {
    const std::string where = "face " + std::to_string(f);
    in.next(where + " of " + std::to_string(faces));
    const long long k = in.count(0, "corner count");
    if (k < 3 || static_cast<long long>(in.size()) < 1 + k)
      in.fail(where, "expected a corner count >= 3 followed by that many vertex indices");
    std::vector<int> corners;
    for (long long c = 1; c <= k; ++c) {
      const long long index = in.integer(c, where, "vertex index");
      if (index < 0 || index >= vertices)
        in.fail(where, "vertex index " + std::to_string(index) + " out of range (" +
                           std::to_string(vertices) + " vertices)");
      corners.push_back(static_cast<int>(index));
    }
    if (!builder.add_polygon(corners)) in.fail(where, "uses the same vertex twice");
  }
  return builder.finish(name);
}

}  // namespace shapectl
