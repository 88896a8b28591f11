#pragma once
// Sums per-element nodal gradients into the global gradient node by node instead of element by
// element: each node adds its elements' contributions itself, in ascending element order. Nodes
// are independent, so all cores add at once without locks or colours, and every entry is summed
// in the same order as the serial element-by-element scatter: the result is that scatter's, bit
// for bit, on any number of threads.
#include <vector>

#include <shapectl/fem/element_hessians.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

class GradientGather {
 public:
  // elements: the nodes of each element (corner k of the whole list is element e's node a for
  // k = elements.offsets[e] + a); node_count: nodes in the gradient (size 3 · node_count).
  GradientGather(const ElementNodes& elements, int node_count);

  // gradient(3i … 3i+2) += Σ per_corner(3k … 3k+2) over the corners k of node i, ascending.
  // per_corner: 3 values (x, y, z) per corner, corners in element order (3 · corner count).
  void add(const double* per_corner, Eigen::VectorXd& gradient) const;

 private:
  std::vector<int> corner_offsets_;  // node i: corners_[corner_offsets_[i] …]
  std::vector<int> corners_;
};

}  // namespace shapectl
