#include <shapectl/fem/hessian_scatter.hpp>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace shapectl
