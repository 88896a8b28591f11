#include <shapectl/mesh/box_mesh.hpp>

#include <cmath>
#include <string>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>

namespace shapectl {

TetMesh make_box_mesh(const Vec3& size, const std::array<int, 3>& cells,
                      const std::optional<BoxHole>& hole) {
  static const char* axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(size[a]) && size[a] > 0))
      throw InputError("box mesh", std::string("size.") + axis_names[a], "a positive finite length",
                       size[a]);
    if (cells[a] < 1)
      throw InputError("box mesh", std::string("cells.") + axis_names[a], "at least 1 cell",
                       cells[a]);
  }
  const long long tet_count = 6LL * cells[0] * cells[1] * cells[2];
  if (tet_count > max_mesh_tets)
    throw InputError("box mesh", "cells",
                     "at most " + std::to_string(max_mesh_tets) + " tetrahedra (6 per cell)",
                     tet_count);
  const int nx = cells[0], ny = cells[1], nz = cells[2];
  auto index = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };

  std::vector<Vec3> rest_positions;
  rest_positions.reserve(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        rest_positions.push_back(Vec3(size.x() * (double(i) / nx - 0.5),
                                      size.y() * (double(j) / ny - 0.5),
                                      size.z() * (double(k) / nz - 0.5)));

  // Kuhn split: one tet per axis order (a, b, c), walking corner 000 -> +e_a -> +e_b -> 111.
  // Corners are bit masks (x = 1, y = 2, z = 4). The tet's orientation is the sign of the
  // permutation, so the odd ones list their last two corners swapped to stay positive.
  static constexpr int kuhn[6][4] = {
      {0, 1, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7},  // xyz, yzx, zxy: even
      {0, 1, 7, 5}, {0, 2, 7, 3}, {0, 4, 7, 6},  // xzy, yxz, zyx: odd, swapped
  };
  std::vector<std::array<int, 4>> tets;
  tets.reserve(6 * static_cast<std::size_t>(nx) * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Vec3 centre =
            0.5 * (rest_positions[index(i, j, k)] + rest_positions[index(i + 1, j + 1, k + 1)]);
        if (hole && (centre - hole->min).minCoeff() > 0 && (hole->max - centre).minCoeff() > 0)
          continue;
        for (const auto& tet : kuhn) {
          std::array<int, 4> t;
          for (int a = 0; a < 4; ++a)
            t[a] = index(i + (tet[a] & 1), j + ((tet[a] >> 1) & 1), k + ((tet[a] >> 2) & 1));
          tets.push_back(t);
        }
      }
  if (hole) {  // drop the nodes only the removed cells used, keeping the others' order
    std::vector<int> renumber(rest_positions.size(), -1);
    for (const auto& t : tets)
      for (int a : t) renumber[a] = 0;
    std::vector<Vec3> kept;
    for (std::size_t i = 0; i < rest_positions.size(); ++i)
      if (renumber[i] == 0) {
        renumber[i] = static_cast<int>(kept.size());
        kept.push_back(rest_positions[i]);
      }
    for (auto& t : tets)
      for (int& a : t) a = renumber[a];
    rest_positions = std::move(kept);
  }
  return TetMesh(std::move(rest_positions), std::move(tets), "box mesh");
}

}  // namespace shapectl
