#include <shapectl/mesh/obj_reader.hpp>

#include <string_view>
#include <vector>

#include <shapectl/mesh/surface_builder.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

TriangleSurface read_obj(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  SurfaceBuilder builder(name);
  while (in.next()) {
    if (in[0] == "v") {
      if (in.size() < 4)
        in.fail("", "expected 'v x y z', found " + std::to_string(in.size() - 1) + " values");
      builder.add_vertex(in.point(1, ""));
    } else if (in[0] == "f") {
      if (in.size() < 4) in.fail("face", "expected at least 3 vertices");
      std::vector<int> corners;
      for (std::size_t k = 1; k < in.size(); ++k) {
        const std::string_view token = in[k].substr(0, in[k].find('/'));
        const long long index = in.integer(token, "face", "vertex index");
        const long long n = builder.vertex_count();
        const long long i = index < 0 ? n + index : index - 1;
        if (index == 0 || i < 0 || i >= n)
          in.fail("face", "vertex index " + std::to_string(index) + " out of range (" +
                              std::to_string(n) + " vertices so far)");
        corners.push_back(static_cast<int>(i));
      }
      if (!builder.add_polygon(corners)) in.fail("face", "uses the same vertex twice");
    }
  }
  return builder.finish(name);
}

}  // namespace shapectl
