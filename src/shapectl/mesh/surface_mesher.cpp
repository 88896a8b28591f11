#include <shapectl/mesh/surface_mesher.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/tetgen_runner.hpp>

namespace shapectl {

namespace {

std::string shown_point(const Vec3& x) {
  std::ostringstream s;
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

// Every edge must be shared by exactly two triangles, or TetGen cannot tell inside from out.
void expect_closed(const TriangleSurface& surface, const std::string& source) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) uses[std::minmax(t[k], t[(k + 1) % 3])]++;
  for (const auto& [edge, count] : uses)
    if (count != 2)
      throw InputError(source, "",
                       "the surface is not closed: edge " +
                           shown_point(surface.vertices[edge.first]) + "-" +
                           shown_point(surface.vertices[edge.second]) + " belongs to " +
                           std::to_string(count) + " triangle" + (count == 1 ? "" : "s") +
                           ", expected 2");
}

// The volume a closed triangle surface encloses (divergence theorem), m^3.
double enclosed_volume(const TriangleSurface& surface) {
  double six_volume = 0;
  for (const auto& t : surface.triangles)
    six_volume += surface.vertices[t[0]].dot(surface.vertices[t[1]].cross(surface.vertices[t[2]]));
  return std::abs(six_volume) / 6;
}

}  // namespace

TetMesh tetrahedralize_surface(const TriangleSurface& surface, const SurfaceMeshOptions& options,
                               const std::string& source) {
  const double ratio = options.max_radius_edge_ratio, volume = options.max_tet_volume;
  const std::string option_file = options.origin_file.empty() ? source : options.origin_file;
  auto option = [&](const std::string& name) {
    return options.origin_path.empty() ? name : options.origin_path + "." + name;
  };
  if (!(std::isfinite(ratio) && (ratio == 0 || ratio >= 1)))
    throw InputError(option_file, option("max_radius_edge_ratio"), "0 (off) or a ratio >= 1",
                     ratio);
  if (!(std::isfinite(volume) && volume >= 0))
    throw InputError(option_file, option("max_tet_volume"),
                     "0 (no bound) or a positive volume in m^3", volume);
  const int n = static_cast<int>(surface.vertices.size());
  for (const auto& t : surface.triangles)
    for (int v : t)
      if (v < 0 || v >= n)
        throw InputError(source, "", "triangle vertex " + std::to_string(v) + " out of range");
  // TetGen's exact predicates overflow on huge coordinates (products of four of them).
  for (int i = 0; i < n; ++i)
    if (!(surface.vertices[i].cwiseAbs().maxCoeff() <= 1e6))
      throw InputError(source, "vertex " + std::to_string(i),
                       "coordinates within 1e6 m of the origin", shown_point(surface.vertices[i]));
  if (surface.triangles.empty()) throw InputError(source, "", "no triangles");
  if (static_cast<long>(surface.triangles.size()) > max_surface_triangles)
    throw InputError(source, "",
                     "more than " + std::to_string(max_surface_triangles) + " triangles");
  expect_closed(surface, source);
  // Refuse a volume bound that asks for more tets than a mesh may have, before TetGen runs.
  const double enclosed = enclosed_volume(surface);
  if (volume > 0 && enclosed / volume > max_tetgen_volume_ratio) {
    std::ostringstream expected;
    expected << "0 (no bound) or at least " << enclosed / max_tetgen_volume_ratio
             << " m^3 (the surface " << source << " encloses " << enclosed << " m^3; at most "
             << max_tetgen_volume_ratio << " times smaller)";
    throw InputError(option_file, option("max_tet_volume"), expected.str(), volume);
  }

  // p: the input is a surface; z: number from 0; Q: quiet.
  std::ostringstream switches;
  switches.precision(17);
  switches << "pzQS" << max_tetgen_added_points;
  if (ratio > 0) switches << "q" << ratio;
  if (volume > 0) switches << "a" << volume;
  if (options.keep_surface) switches << "Y";
  TetgenOutput out = run_tetgen(surface, switches.str(), source);
  // TetGen quietly stops refining when -S runs out: the mesh would not meet the options.
  if (static_cast<long>(out.points.size()) - n >= max_tetgen_added_points)
    throw InputError(option_file, options.origin_path,
                     "TetGen needed more than " + std::to_string(max_tetgen_added_points) +
                         " added points for these options; allow larger or less regular "
                         "tets (a larger max_tet_volume or max_radius_edge_ratio)");
  if (static_cast<long>(out.tets.size()) > max_mesh_tets)
    throw InputError(source, "",
                     "TetGen made " + std::to_string(out.tets.size()) +
                         " tetrahedra, more than the limit of " + std::to_string(max_mesh_tets));

  // TetGen keeps the input points first; a surface vertex it dropped would break that promise.
  for (int i = 0; i < n; ++i)
    if (i >= static_cast<int>(out.points.size()) || out.points[i] != surface.vertices[i])
      throw InputError(source, "vertex " + std::to_string(i), "TetGen moved or dropped it");
  // TetGen 1.5 writes positively oriented tets (volume of (a, b, c, d) > 0), as TetMesh wants.
  return TetMesh(std::move(out.points), std::move(out.tets), source);
}

TetMesh mesh_surface(const std::filesystem::path& file, const SurfaceMeshOptions& options) {
  return tetrahedralize_surface(read_surface(file), options, file.string());
}

}  // namespace shapectl
