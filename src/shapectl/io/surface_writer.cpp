#include <shapectl/io/surface_writer.hpp>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <shapectl/io/ascii_case.hpp>

namespace shapectl {

namespace {

void check_sizes(const Positions& positions, const std::vector<std::array<int, 3>>& triangles) {
  if (positions.size() % 3 != 0)
    throw std::invalid_argument("surface_text: positions size " + std::to_string(positions.size()) +
                                " is not a multiple of 3");
  if (!positions.allFinite()) throw std::invalid_argument("surface_text: a position is not finite");
  const long n = static_cast<long>(positions.size() / 3);
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || v >= n)
        throw std::invalid_argument("surface_text: triangle node " + std::to_string(v) +
                                    " out of range (" + std::to_string(n) + " nodes)");
}

void write_ply(std::ostream& out, const Positions& x,
               const std::vector<std::array<int, 3>>& triangles) {
  out << "ply\nformat ascii 1.0\ncomment shapectl deformed surface, metres\n"
      << "element vertex " << x.size() / 3 << "\nproperty double x\nproperty double y\n"
      << "property double z\nelement face " << triangles.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < x.size(); i += 3)
    out << x[i] << ' ' << x[i + 1] << ' ' << x[i + 2] << '\n';
  for (const auto& t : triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void write_obj(std::ostream& out, const Positions& x,
               const std::vector<std::array<int, 3>>& triangles) {
  out << "# shapectl deformed surface, metres\n";
  for (Eigen::Index i = 0; i < x.size(); i += 3)
    out << "v " << x[i] << ' ' << x[i + 1] << ' ' << x[i + 2] << '\n';
  // OBJ counts vertices from 1.
  for (const auto& t : triangles)
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

}  // namespace

std::optional<SurfaceFormat> surface_format(const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  if (ext == ".ply") return SurfaceFormat::Ply;
  if (ext == ".obj") return SurfaceFormat::Obj;
  return std::nullopt;
}

std::string surface_text(SurfaceFormat format, const Positions& positions,
                         const std::vector<std::array<int, 3>>& triangles) {
  check_sizes(positions, triangles);
  std::ostringstream out;
  out.precision(std::numeric_limits<double>::max_digits10);
  if (format == SurfaceFormat::Ply) write_ply(out, positions, triangles);
  else write_obj(out, positions, triangles);
  return out.str();
}

}  // namespace shapectl
