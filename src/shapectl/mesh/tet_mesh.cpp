#include <shapectl/mesh/tet_mesh.hpp>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {
std::string fmt_double(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

TetMesh::TetMesh(std::vector<Vec3> rest_positions, std::vector<std::array<int, 4>> tets,
                 const std::string& source)
    : rest_positions_(std::move(rest_positions)) {
  const int n = node_count();
  for (int i = 0; i < n; ++i)
    if (!rest_positions_[i].allFinite())
      throw InputError(source, "node " + std::to_string(i), "coordinates are not finite");
  if (tets.empty()) throw InputError(source, "", "the mesh has no tetrahedra");

  // A degenerate tet is one whose volume is tiny next to the cube of its longest edge.
  std::vector<char> used(n, 0);
  tets_.reserve(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    const auto& t = tets[e];
    // Made only for an error: a valid mesh should not pay a heap string per tet.
    auto where = [e] { return "element " + std::to_string(e); };
    for (int a = 0; a < 4; ++a) {
      if (t[a] < 0 || t[a] >= n)
        throw InputError(source, where(),
                         "node " + std::to_string(t[a]) + " out of range (mesh has " +
                             std::to_string(n) + " nodes)");
      for (int b = 0; b < a; ++b)
        if (t[a] == t[b])
          throw InputError(source, where(), "node " + std::to_string(t[a]) + " appears twice");
    }
    Mat3 Dm;
    double longest = 0;
    for (int c = 0; c < 3; ++c) Dm.col(c) = rest_positions_[t[c + 1]] - rest_positions_[t[0]];
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        longest = std::max(longest, (rest_positions_[t[a]] - rest_positions_[t[b]]).norm());
    const double volume = Dm.determinant() / 6.0;
    if (std::abs(volume) <= 1e-9 * longest * longest * longest)
      throw InputError(source, where(),
                       "degenerate tetrahedron (volume " + fmt_double(volume) + ")");
    if (volume < 0)
      throw InputError(source, where(), "inverted tetrahedron (volume " + fmt_double(volume) + ")");
    tets_.push_back({t, volume, Dm.inverse()});
    for (int a : t) used[a] = 1;
  }
  for (int i = 0; i < n; ++i)
    if (!used[i]) isolated_nodes_.push_back(i);
}

Positions TetMesh::rest_vector() const {
  Positions x(3 * node_count());
  for (int i = 0; i < node_count(); ++i) x.segment<3>(3 * i) = rest_positions_[i];
  return x;
}

double TetMesh::total_volume() const {
  double v = 0;
  for (const auto& t : tets_) v += t.volume;
  return v;
}

Vec3 TetMesh::bounds_min() const {
  Vec3 m = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (const auto& p : rest_positions_) m = m.cwiseMin(p);
  return m;
}

Vec3 TetMesh::bounds_max() const {
  Vec3 m = Vec3::Constant(-std::numeric_limits<double>::infinity());
  for (const auto& p : rest_positions_) m = m.cwiseMax(p);
  return m;
}

std::vector<std::array<int, 3>> TetMesh::surface_triangles() const {
  // Faces of a positively oriented tet (a,b,c,d), each wound outward.
  static constexpr int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::map<std::array<int, 3>, std::pair<int, std::array<int, 3>>> count;
  for (const auto& t : tets_)
    for (const auto& f : faces) {
      std::array<int, 3> tri = {t.nodes[f[0]], t.nodes[f[1]], t.nodes[f[2]]};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto& entry = count[key];
      entry.first++;
      entry.second = tri;
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& [key, entry] : count)
    if (entry.first == 1) out.push_back(entry.second);
  return out;
}

}  // namespace shapectl
