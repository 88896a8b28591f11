#pragma once
// The pattern of a FEM Hessian seen node by node. A Hessian over the x, y, z of n nodes is made
// of 3×3 blocks, one per pair of nodes sharing an element (a held dof keeps only its diagonal).
// Orderings and flop counts found on the n×n node pattern hold for the 3n×3n matrix and cost a
// ninth of the entries and a fraction of the time: a fill-reducing ordering of the nodes
// numbers each node's three dofs together, and a node column of length c stands for three dof
// columns of about 3c, so ~27x its flops.
#include <optional>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// The node pattern (lower triangle, diagonal always stored, values zero) of `lower`, a
// lower-triangle compressed matrix of size 3n; nullopt unless `lower` is exactly in node
// blocks: wherever a node pair has an entry, it has every entry of the pair's lower triangle
// except the rows and columns of dofs that touch nothing but their own diagonal.
std::optional<SparseMatrix> node_pattern(const SparseMatrix& lower);

// The dof order of a node order: node_order[k] is the old index of the k-th node; the result's
// 3k + c is the old dof 3 node_order[k] + c.
std::vector<int> dof_order(const std::vector<int>& node_order);

}  // namespace shapectl
