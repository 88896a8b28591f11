#include <shapectl/fem/hessian_scatter.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

namespace shapectl {
namespace {

// A fan: 100 two-node elements all sharing node 0, more than one 64-colour round can hold;
// each block is all ones, so every value is a count of the elements that touch it.
TEST(HessianScatter, AddsEveryBlockOnceWhenANodeIsInMoreThan64Elements) {
  const int spokes = 100;
  ElementNodes fan;
  for (int i = 1; i <= spokes; ++i) fan.add({0, i});
  const int dofs = 3 * (spokes + 1);
  std::vector<char> fixed_dof(dofs, 0);
  fixed_dof[3 * 7 + 1] = 1;  // one held dof: its row and column are dropped
  SparseMatrix H;
  const HessianScatter scatter(dofs, fixed_dof, {fan}, H);
  scatter.add_blocks(
      0, [](std::size_t, double* block) { std::fill(block, block + 36, 1.0); }, H.valuePtr());

  for (int c = 0; c < dofs; ++c)
    for (int r = 0; r < dofs; ++r) {
      const int row_node = r / 3, col_node = c / 3;
      double expected = 0;
      if (r < c || fixed_dof[r] || fixed_dof[c]) expected = 0;
      else if (row_node == 0 && col_node == 0) expected = spokes;
      else if (row_node == col_node || col_node == 0) expected = 1;
      EXPECT_EQ(H.coeff(r, c), expected) << "(" << r << ", " << c << ")";
    }
  // Only the lower triangle is stored, a held dof's column only on its diagonal.
  EXPECT_EQ(H.col(3 * 7 + 1).nonZeros(), 1);
  ASSERT_EQ(scatter.fixed_diagonal_slots().size(), 1u);
  EXPECT_EQ(H.innerIndexPtr()[scatter.fixed_diagonal_slots()[0]], 3 * 7 + 1);
}

// A symmetric pseudo-random block entry of element e at (row i, column j).
double block_entry(std::size_t e, int i, int j) {
  const unsigned h =
      2654435761u * static_cast<unsigned>(e + 1) + 40503u * std::min(i, j) + 977u * std::max(i, j);
  return static_cast<double>(h % 2001) / 1000.0 - 1.0;
}

TEST(HessianScatter, AddsWhatADenseSumDoesForFreePartlyHeldAndHeldNodes) {
  // Two terms over 12 nodes: tets, and one- and two-node elements, one of which lists a node
  // twice. Node 4 is partly held, node 9 fully: blocks between free nodes go in whole 3×3
  // pieces, those with node 4 entry by entry, those with node 9 not at all. Every free entry
  // of the lower triangle must equal the dense sum of the blocks.
  const int node_count = 12, dofs = 3 * node_count;
  std::vector<char> fixed_dof(dofs, 0);
  fixed_dof[3 * 4 + 0] = fixed_dof[3 * 4 + 2] = 1;
  for (int k = 0; k < 3; ++k) fixed_dof[3 * 9 + k] = 1;
  ElementNodes tets, small;
  for (const auto& t : std::vector<std::array<int, 4>>{
           {0, 1, 2, 3}, {3, 2, 1, 4}, {4, 5, 6, 7}, {7, 8, 9, 10}, {10, 11, 0, 5}, {2, 6, 9, 11}})
    tets.add({t[0], t[1], t[2], t[3]});
  small.add({3});
  small.add({4});
  small.add({9});
  small.add({5, 5});
  small.add({8, 1});
  const std::vector<ElementNodes> terms = {tets, small};
  SparseMatrix H;
  const HessianScatter scatter(dofs, fixed_dof, terms, H);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(dofs, dofs);
  for (std::size_t t = 0; t < terms.size(); ++t) {
    std::size_t first = t == 0 ? 0 : tets.size();  // distinct blocks for the two terms
    scatter.add_blocks(
        t,
        [&](std::size_t e, double* block) {
          const int k = 3 * terms[t].node_count(e);
          for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i) block[j * k + i] = block_entry(first + e, i, j);
        },
        H.valuePtr());
    for (std::size_t e = 0; e < terms[t].size(); ++e) {
      const int* nodes = terms[t].begin(e);
      for (int a = 0; a < terms[t].node_count(e); ++a)
        for (int b = 0; b < terms[t].node_count(e); ++b)
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
              dense(3 * nodes[a] + r, 3 * nodes[b] + c) +=
                  block_entry(first + e, 3 * a + r, 3 * b + c);
    }
  }
  int compared = 0;
  for (int c = 0; c < dofs; ++c)
    for (int r = c; r < dofs; ++r) {
      if (fixed_dof[r] || fixed_dof[c]) {
        EXPECT_EQ(H.coeff(r, c), 0.0) << "(" << r << ", " << c << ")";
        continue;
      }
      EXPECT_NEAR(H.coeff(r, c), dense(r, c), 1e-12) << "(" << r << ", " << c << ")";
      compared += dense(r, c) != 0;
    }
  EXPECT_GT(compared, 200);  // the blocks do reach the matrix
  EXPECT_EQ(scatter.fixed_diagonal_slots().size(), 5u);
}

}  // namespace
}  // namespace shapectl
