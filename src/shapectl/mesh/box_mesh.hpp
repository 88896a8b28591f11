#pragma once
// A structured tetrahedral box, the default test and demo object.
#include <array>
#include <optional>

#include <shapectl/mesh/tet_mesh.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

// A box centred at the origin spanning [-size/2, size/2] (metres), with cells[0] x cells[1] x
// cells[2] hexahedral cells, each split into 6 positively oriented tets along its main diagonal
// (Kuhn split, conforming across cells). Node (i, j, k) has index i + (nx+1)*(j + (ny+1)*k).
// Throws InputError unless every size component is positive and finite, every cell count >= 1
// and the box has at most max_mesh_tets tets.
// The default bar: make_box_mesh({0.32, 0.03, 0.03}, {16, 4, 4}) has 425 nodes and 1536 tets.
// Cells whose centre lies inside the hole are left out (e.g. a frame); nodes that only they
// used are dropped, the rest keep their order.
struct BoxHole {
  Vec3 min, max;
};
TetMesh make_box_mesh(const Vec3& size, const std::array<int, 3>& cells,
                      const std::optional<BoxHole>& hole = std::nullopt);

}  // namespace shapectl
