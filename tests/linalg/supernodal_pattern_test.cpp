#include <shapectl/linalg/supernodal_pattern.hpp>

#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <random>

#include <shapectl/linalg/supernodal_llt.hpp>
#include <shapectl/types.hpp>

namespace shapectl {
namespace {

// CHOLMOD's supernodal analysis of `lower` in its natural order, with or without merging
// supernodes (merged ones hold explicit zeros).
SupernodalPattern analysed(const SparseMatrix& lower, bool merge) {
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_NATURAL;
  common.postorder = 0;
  if (!merge) {
    for (auto& n : common.nrelax) n = 0;
    for (auto& z : common.zrelax) z = 0;
  }
  cholmod_sparse a = Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
  cholmod_factor* factor = cholmod_analyze(&a, &common);
  EXPECT_TRUE(factor);
  SupernodalPattern pattern = supernodal_pattern(*factor);
  cholmod_free_factor(&factor, &common);
  cholmod_finish(&common);
  return pattern;
}

// A random symmetric positive definite matrix of `nodes` × `nodes` dense 3×3 blocks (lower
// triangle), and its pattern of blocks.
struct BlockMatrix {
  SparseMatrix dofs, nodes;
};
BlockMatrix random_block_matrix(int nodes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> node(0, nodes - 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3 * nodes, 3 * nodes);
  Eigen::MatrixXi coupled = Eigen::MatrixXi::Identity(nodes, nodes);
  for (int j = 0; j < nodes; ++j)
    for (int k = 0; k < 2; ++k) {
      const int i = node(rng);
      coupled(std::max(i, j), std::min(i, j)) = 1;
    }
  for (int j = 0; j < nodes; ++j)
    for (int i = j; i < nodes; ++i)
      if (coupled(i, j)) a.block<3, 3>(3 * i, 3 * j) = Eigen::Matrix3d::Random();
  const Eigen::MatrixXd lower_full = a.triangularView<Eigen::StrictlyLower>();
  Eigen::MatrixXd spd = lower_full + lower_full.transpose();
  spd.diagonal().array() = spd.cwiseAbs().rowwise().sum().array() + 1;  // diagonally dominant
  BlockMatrix m;
  m.dofs = Eigen::MatrixXd(spd.triangularView<Eigen::Lower>()).sparseView();
  m.nodes = coupled.cast<double>().sparseView();
  m.dofs.makeCompressed();
  m.nodes.makeCompressed();
  return m;
}

TEST(SupernodalPattern, ExpandedNodeFactorIsTheDofFactor) {
  const BlockMatrix m = random_block_matrix(60, 5);
  // Without merging, the expansion is exactly CHOLMOD's analysis of the dofs: the same
  // supernodes, rows and flops.
  const SupernodalPattern expanded = expand_blocks(analysed(m.nodes, false), 3);
  const SupernodalPattern of_dofs = analysed(m.dofs, false);
  EXPECT_EQ(expanded.first_column, of_dofs.first_column);
  EXPECT_EQ(expanded.row_starts, of_dofs.row_starts);
  EXPECT_EQ(expanded.row_index, of_dofs.row_index);
  EXPECT_EQ(expanded.value_starts, of_dofs.value_starts);
  EXPECT_DOUBLE_EQ(expanded.flops(), of_dofs.flops());
  EXPECT_GT(expanded.count(), 10);
  // With merging, our kernels factor the dofs on the expanded pattern: L Lᵀ solves as a dense
  // Cholesky does.
  const SupernodalPattern merged = expand_blocks(analysed(m.nodes, true), 3);
  EXPECT_LT(merged.count(), expanded.count());
  std::vector<double> values(merged.value_count());
  ASSERT_TRUE(factorize_supernodal(m.dofs, merged, supernodal_teams(merged), values.data()));
  const Eigen::MatrixXd full = SparseMatrix(m.dofs.selfadjointView<Eigen::Lower>());
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(m.dofs.rows(), -1, 2);
  const Eigen::VectorXd expected = full.llt().solve(x);
  solve_supernodal_in_place(merged, values.data(), x);
  EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
}

TEST(SupernodalPattern, FlopsCountEachColumnsEntriesSquared) {
  // A dense 4×4 matrix: one supernode whose columns hold 4, 3, 2 and 1 entries.
  const Eigen::MatrixXd dense = Eigen::MatrixXd::Ones(4, 4) + 4 * Eigen::MatrixXd::Identity(4, 4);
  const SparseMatrix lower = Eigen::MatrixXd(dense.triangularView<Eigen::Lower>()).sparseView();
  const SupernodalPattern pattern = analysed(lower, false);
  ASSERT_EQ(pattern.count(), 1);
  EXPECT_EQ(pattern.size(), 4);
  EXPECT_EQ(pattern.value_count(), 16u);
  EXPECT_DOUBLE_EQ(pattern.flops(), 16 + 9 + 4 + 1);
}

}  // namespace
}  // namespace shapectl
