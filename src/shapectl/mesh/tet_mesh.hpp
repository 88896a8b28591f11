#pragma once
// A linear tetrahedral mesh at rest, with the per-element data FEM needs.
#include <array>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct TetRest {
  std::array<int, 4> nodes;  // node indices, positively oriented (volume > 0)
  double volume;             // rest volume, m^3
  Mat3 Dm_inverse;           // inverse of [X1-X0, X2-X0, X3-X0]
};

class TetMesh {
 public:
  // Validates and precomputes rest data. `source` names the input in error messages.
  // Throws InputError for out-of-range indices, repeated nodes in a tet, non-finite coordinates,
  // and degenerate or inverted elements (naming the element and its volume).
  TetMesh(std::vector<Vec3> rest_positions, std::vector<std::array<int, 4>> tets,
          const std::string& source = "mesh");

  int node_count() const { return static_cast<int>(rest_positions_.size()); }
  int tet_count() const { return static_cast<int>(tets_.size()); }
  const std::vector<Vec3>& rest_positions() const { return rest_positions_; }
  const std::vector<TetRest>& tets() const { return tets_; }
  // Stacked rest positions [X0; X1; ...], size 3n.
  Positions rest_vector() const;
  // Nodes used by no tetrahedron (allowed: they stay where they are and carry no mass).
  const std::vector<int>& isolated_nodes() const { return isolated_nodes_; }
  double total_volume() const;
  // Axis-aligned bounding box of the rest positions.
  Vec3 bounds_min() const;
  Vec3 bounds_max() const;
  // Boundary triangles (faces used by one tet), outward oriented.
  std::vector<std::array<int, 3>> surface_triangles() const;

 private:
  std::vector<Vec3> rest_positions_;
  std::vector<TetRest> tets_;
  std::vector<int> isolated_nodes_;
};

}  // namespace shapectl
