#include <shapectl/linalg/sparse_cholesky.hpp>

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

#include <shapectl/linalg/band_cholesky.hpp>
#include <shapectl/linalg/node_pattern.hpp>
#include <shapectl/linalg/permuted_cholmod.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "support/linear_solvers.hpp"

namespace shapectl {
namespace {

using Backend = SparseCholesky::Backend;

// A foam box clamped at its -x end.
Scene clamped_box(const Vec3& size, const std::array<int, 3>& cells) {
  Scene s;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh(size, cells));
  s.material = material_from_youngs(2e5, 0.3, 40);
  NodeSelection fixed;
  fixed.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-size.x() / 2 + 1e-3, 1, 1)};
  s.fixed = fixed;
  return s;
}

// The true Hessian of a sagging box at its equilibrium (lower triangle).
SparseMatrix equilibrium_hessian(const Scene& scene) {
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  EXPECT_TRUE(statics.solve(x).converged());
  return statics.hessian(x);
}

SparseMatrix bar_hessian() {
  return equilibrium_hessian(clamped_box({0.32, 0.03, 0.03}, {16, 4, 4}));
}

int bandwidth(const SparseMatrix& lower, const std::vector<int>& new_index) {
  int b = 0;
  for (int j = 0; j < lower.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(lower, j); it; ++it)
      b = std::max(b, std::abs(new_index[it.row()] - new_index[j]));
  return b;
}

TEST(SparseCholesky, EveryBackendSolvesTheBarHessian) {
  const SparseMatrix H = bar_hessian();
  const Eigen::MatrixXd full = SparseMatrix(H.selfadjointView<Eigen::Lower>());
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(H.rows(), 14);
  const Eigen::MatrixXd reference = full.llt().solve(rhs);
  for (Backend backend : test::kLinearSolvers) {
    SparseCholesky cholesky(backend);
    cholesky.analyze(H);
    ASSERT_TRUE(cholesky.factorize(H)) << to_string(backend);
    const Eigen::MatrixXd y = cholesky.solve(rhs);
    EXPECT_LT((y - reference).norm(), 1e-9 * reference.norm()) << to_string(backend);
    const Eigen::VectorXd y0 = cholesky.solve(Eigen::VectorXd(rhs.col(0)));
    EXPECT_LT((y0 - reference.col(0)).norm(), 1e-9 * reference.col(0).norm());
  }
}

TEST(SparseCholesky, EveryBackendRefusesIndefiniteAndSingularMatrices) {
  SparseMatrix indefinite = bar_hessian(), singular = indefinite;
  const int middle = static_cast<int>(indefinite.rows()) / 2;
  indefinite.coeffRef(middle, middle) = -indefinite.coeff(middle, middle);
  // Singular: one unknown's row and column become zero.
  for (int j = 0; j < singular.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(singular, j); it; ++it)
      if (it.row() == middle || j == middle) it.valueRef() = 0;
  for (Backend backend : test::kLinearSolvers) {
    SparseCholesky cholesky(backend);
    cholesky.analyze(indefinite);
    EXPECT_FALSE(cholesky.factorize(indefinite)) << to_string(backend);
    EXPECT_FALSE(cholesky.factorize(singular)) << to_string(backend);
  }
}

TEST(ReverseCuthillMckee, RecoversANarrowBandFromAShuffledNumbering) {
  const SparseMatrix H = bar_hessian();
  const int n = static_cast<int>(H.rows());
  std::vector<int> identity(n);
  for (int i = 0; i < n; ++i) identity[i] = i;
  // Renumber the unknowns at random: the band of the natural (slice-by-slice) numbering is gone.
  std::vector<int> shuffle = identity;
  std::shuffle(shuffle.begin(), shuffle.end(), std::mt19937(7));
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(n);
  for (int i = 0; i < n; ++i) P.indices()[i] = shuffle[i];
  SparseMatrix full_shuffled;
  full_shuffled = H.selfadjointView<Eigen::Lower>().twistedBy(P);
  const SparseMatrix shuffled = full_shuffled.triangularView<Eigen::Lower>();
  ASSERT_GT(bandwidth(shuffled, identity), n / 2);

  const std::vector<int> order = reverse_cuthill_mckee(shuffled);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  ASSERT_EQ(sorted, identity);  // a permutation
  std::vector<int> new_index(n);
  for (int k = 0; k < n; ++k) new_index[order[k]] = k;
  // The box mesh numbers nodes slice by slice along the bar: a good band. RCM finds one as
  // narrow from the shuffled numbering.
  EXPECT_LE(bandwidth(shuffled, new_index), bandwidth(H, identity));

  BandCholesky band;
  band.analyze(shuffled);
  EXPECT_EQ(band.bandwidth(), bandwidth(shuffled, new_index));
}

SparseMatrix rest_hessian(const Scene& scene) {
  ObjectStatics statics(scene);
  return statics.hessian(scene.world_rest_positions());
}

TEST(SparseCholesky, AutomaticChoiceFollowsTheMeshShape) {
  // Elongated or small meshes: the band (at most 2x CHOLMOD's flops, 8x LDLᵀ's below 2,500
  // unknowns; docs/benchmarks.md, "the back-end choice, again").
  for (const auto& [size, cells] : {std::pair{Vec3(0.32, 0.03, 0.03), std::array{16, 4, 4}},
                                    std::pair{Vec3(0.08, 0.08, 0.08), std::array{8, 8, 8}},
                                    std::pair{Vec3(0.64, 0.12, 0.11), std::array{64, 12, 11}}}) {
    SparseCholesky cholesky;
    cholesky.analyze(rest_hessian(clamped_box(size, cells)));
    EXPECT_EQ(cholesky.backend(), Backend::Band) << cells[0] << "x" << cells[1] << "x" << cells[2];
  }
  // Compact blocks and a wide plate: CHOLMOD, whose flops are under half the band's.
  for (const auto& [size, cells] : {std::pair{Vec3(0.14, 0.14, 0.14), std::array{14, 14, 14}},
                                    std::pair{Vec3(0.2, 0.2, 0.2), std::array{20, 20, 20}},
                                    std::pair{Vec3(0.4, 0.4, 0.01), std::array{40, 40, 1}}}) {
    SparseCholesky cholesky;
    cholesky.analyze(rest_hessian(clamped_box(size, cells)));
    EXPECT_EQ(cholesky.backend(), Backend::CholmodSupernodal)
        << cells[0] << "x" << cells[1] << "x" << cells[2];
  }
}

TEST(SparseCholesky, LdltFlopEstimateFromNodesMatchesEigensAnalysisOfTheDofs) {
  // Under 2,500 unknowns the band competes with Eigen's LDLᵀ, whose flops come from AMD on the
  // node pattern: close to those of Eigen's own ordering and analysis of the dofs (2-5 % on
  // these; a missing factor 27, or the pairs counted as flops, would be far off).
  for (const auto& [size, cells] : {std::pair{Vec3(0.32, 0.03, 0.03), std::array{16, 4, 4}},
                                    std::pair{Vec3(0.36, 0.36, 0.01), std::array{18, 18, 1}},
                                    std::pair{Vec3(0.08, 0.08, 0.08), std::array{6, 6, 6}}}) {
    const SparseMatrix H = rest_hessian(clamped_box(size, cells));
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower> llt(H);
    ASSERT_EQ(llt.info(), Eigen::Success);
    const SparseMatrix L = llt.matrixL();
    double eigen_flops = 0;
    for (int j = 0; j < L.outerSize(); ++j)
      eigen_flops += double(L.col(j).nonZeros()) * double(L.col(j).nonZeros());
    const double estimate = ldlt_flops_by_nodes(*node_pattern(H));
    EXPECT_GT(estimate, 0.67 * eigen_flops) << cells[0] << "x" << cells[1] << "x" << cells[2];
    EXPECT_LT(estimate, 1.5 * eigen_flops) << cells[0] << "x" << cells[1] << "x" << cells[2];
  }
}

TEST(SparseCholesky, CholmodGivenTheChoicesNodeOrderSolvesAsWithItsOwnAnalysis) {
  // The automatic choice hands CHOLMOD the ordering it found on the nodes, so that CHOLMOD does
  // not order the dofs again; the factor solves as the one of CHOLMOD's own analysis does.
  const SparseMatrix H = rest_hessian(clamped_box(Vec3(0.4, 0.4, 0.01), {40, 40, 1}));
  SparseCholesky automatic, own(Backend::CholmodSupernodal);
  automatic.analyze(H);
  own.analyze(H);
  ASSERT_EQ(automatic.backend(), Backend::CholmodSupernodal);
  ASSERT_TRUE(automatic.factorize(H));
  ASSERT_TRUE(own.factorize(H));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(H.rows(), -1, 1);
  const Eigen::VectorXd x = automatic.solve(b), y = own.solve(b);
  // Backward stable: a residual of round-off times |H| |x|.
  const double scale = H.cwiseAbs().sum() / H.rows() * x.norm();
  EXPECT_LT((H.selfadjointView<Eigen::Lower>() * x - b).norm(), 1e-12 * scale);
  EXPECT_LT((x - y).norm(), 1e-6 * y.norm());
}

TEST(PermutedCholmod, SolvesInAnyOrderGivenAsInItsOwn) {
  // P H Pᵀ, gathered by us, factored by our kernels and by CHOLMOD's: in CHOLMOD's own order of
  // the dofs, in a random one (a poor order, but a permutation all the same), and in its order
  // of the nodes (analyze_nodes: whole node blocks).
  const SparseMatrix H = rest_hessian(clamped_box(Vec3(0.2, 0.2, 0.05), {8, 8, 3}));
  const int n = static_cast<int>(H.rows());
  const Eigen::MatrixXd full = SparseMatrix(H.selfadjointView<Eigen::Lower>());
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(n, 3);
  const Eigen::MatrixXd reference = full.llt().solve(rhs);
  std::vector<int> shuffled(n);
  for (int i = 0; i < n; ++i) shuffled[i] = i;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
  const std::vector<int> by_nodes{-1};
  for (const std::vector<int>& order : {std::vector<int>{}, shuffled, by_nodes})
    for (const double own_kernels_below : {PermutedCholmod::kOwnKernelsBelowFlops, 0.0}) {
      SCOPED_TRACE(testing::Message() << "order "
                                      << (order.empty()       ? "CHOLMOD's"
                                          : order == by_nodes ? "of the nodes"
                                                              : "random")
                                      << ", own kernels below " << own_kernels_below << " flops");
      PermutedCholmod cholmod(own_kernels_below);
      if (order == by_nodes) cholmod.analyze_nodes(H, *node_pattern(H));
      else cholmod.analyze(H, order);
      EXPECT_GT(cholmod.flops(), 0);
      EXPECT_EQ(cholmod.own_kernels(), own_kernels_below > 0);
      ASSERT_TRUE(cholmod.factorize(H));
      EXPECT_LT((cholmod.solve(rhs) - reference).norm(), 1e-9 * reference.norm());
      const Eigen::VectorXd first = cholmod.solve(Eigen::VectorXd(rhs.col(0)));
      EXPECT_LT((first - reference.col(0)).norm(), 1e-9 * reference.norm());
    }
}

// Our kernels or CHOLMOD's; the analysis of the dofs or of the nodes.
class PermutedCholmodKernels : public testing::TestWithParam<std::tuple<double, bool>> {
 protected:
  PermutedCholmod analysed(const SparseMatrix& H) {
    const auto [own_kernels_below, by_nodes] = GetParam();
    PermutedCholmod cholmod(own_kernels_below);
    if (by_nodes) cholmod.analyze_nodes(H, *node_pattern(H));
    else cholmod.analyze(H);
    EXPECT_EQ(cholmod.own_kernels(), own_kernels_below > 0);
    return cholmod;
  }
};

TEST_P(PermutedCholmodKernels, GathersEachNewMatrixAndRefusesAnIndefiniteOrOtherPattern) {
  const SparseMatrix H = bar_hessian();
  PermutedCholmod cholmod = analysed(H);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(H.rows(), -1, 1);
  EXPECT_THROW(cholmod.solve(b), std::logic_error) << "no factor yet";
  ASSERT_TRUE(cholmod.factorize(H));
  const Eigen::VectorXd x = cholmod.solve(b);
  ASSERT_TRUE(cholmod.factorize(2 * H));  // same pattern, new values
  EXPECT_LT((2 * cholmod.solve(b) - x).norm(), 1e-9 * x.norm());
  SparseMatrix indefinite = H;
  const int middle = static_cast<int>(H.rows()) / 2;
  indefinite.coeffRef(middle, middle) = -H.coeff(middle, middle);
  EXPECT_FALSE(cholmod.factorize(indefinite));
  EXPECT_THROW(cholmod.solve(b), std::logic_error) << "the failed factor";
  SparseMatrix not_finite = H;
  not_finite.coeffRef(middle + 1, middle) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(cholmod.factorize(not_finite));
  SparseMatrix fewer = H;
  fewer.prune([&](Eigen::Index row, Eigen::Index col, double) { return row != col + 1; });
  EXPECT_THROW(cholmod.factorize(fewer), std::logic_error);
}

// A FEM Hessian with partly held nodes too: a held dof keeps only its diagonal, so the node
// blocks of such a node are not whole.
TEST_P(PermutedCholmodKernels, SolvesAHessianWithPartlyHeldNodes) {
  SparseMatrix H = bar_hessian();
  const std::set<Eigen::Index> held{3 * 30 + 1, 3 * 41, 3 * 41 + 2, 3 * 77 + 2};
  H.prune([&](Eigen::Index row, Eigen::Index col, double) {
    return row == col || (!held.count(row) && !held.count(col));
  });
  for (const Eigen::Index d : held) H.coeffRef(d, d) = 1;
  ASSERT_TRUE(node_pattern(H));
  PermutedCholmod cholmod = analysed(H);
  ASSERT_TRUE(cholmod.factorize(H));
  const Eigen::MatrixXd full = SparseMatrix(H.selfadjointView<Eigen::Lower>());
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(H.rows(), 2);
  const Eigen::MatrixXd reference = full.llt().solve(rhs);
  EXPECT_LT((cholmod.solve(rhs) - reference).norm(), 1e-9 * reference.norm());
}

INSTANTIATE_TEST_SUITE_P(OwnAndCholmods, PermutedCholmodKernels,
                         testing::Combine(testing::Values(PermutedCholmod::kOwnKernelsBelowFlops,
                                                          0.0),
                                          testing::Bool()));

TEST(PermutedCholmod, RefusesANodePatternThatIsNotTheMatrixs) {
  const SparseMatrix H = bar_hessian();
  const SparseMatrix nodes = *node_pattern(H);
  PermutedCholmod cholmod;
  // A node pair of the matrix missing.
  SparseMatrix fewer = nodes;
  fewer.prune([](Eigen::Index row, Eigen::Index col, double) { return row == col; });
  EXPECT_THROW(cholmod.analyze_nodes(H, fewer), std::logic_error);
  // A diagonal missing (of a free node, with neighbours).
  SparseMatrix no_diagonal = nodes;
  const Eigen::Index middle = nodes.cols() / 2;
  ASSERT_GT(nodes.col(middle).nonZeros(), 1);
  no_diagonal.prune(
      [&](Eigen::Index row, Eigen::Index col, double) { return row != col || row != middle; });
  EXPECT_THROW(cholmod.analyze_nodes(H, no_diagonal), std::logic_error);
  // Another size.
  const SparseMatrix smaller = nodes.topLeftCorner(nodes.rows() - 1, nodes.cols() - 1);
  EXPECT_THROW(cholmod.analyze_nodes(H, smaller), std::logic_error);
}

TEST(NodePattern, AFemHessianIsItsNodePatternInBlocks) {
  const SparseMatrix H = bar_hessian();  // clamped: the held dofs keep only their diagonal
  const std::optional<SparseMatrix> nodes = node_pattern(H);
  ASSERT_TRUE(nodes);
  ASSERT_EQ(3 * nodes->rows(), H.rows());
  std::set<std::pair<int, int>> from_dofs, from_nodes;
  for (int j = 0; j < H.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(H, j); it; ++it)
      from_dofs.insert({static_cast<int>(it.row()) / 3, j / 3});
  for (int j = 0; j < nodes->outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(*nodes, j); it; ++it)
      from_nodes.insert({static_cast<int>(it.row()), j});
  EXPECT_EQ(from_nodes, from_dofs);
  EXPECT_EQ(dof_order({2, 0, 1}), (std::vector<int>{6, 7, 8, 0, 1, 2, 3, 4, 5}));
}

TEST(NodePattern, AMatrixNotInNodeBlocksHasNone) {
  const SparseMatrix H = bar_hessian();
  // One coupling entry less: its node pair is still there, the block is not whole.
  std::vector<Eigen::Triplet<double>> entries;
  bool dropped = false;
  for (int j = 0; j < H.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(H, j); it; ++it) {
      if (!dropped && it.row() / 3 != j / 3) {
        dropped = true;
        continue;
      }
      entries.emplace_back(static_cast<int>(it.row()), j, it.value());
    }
  ASSERT_TRUE(dropped);
  SparseMatrix holed(H.rows(), H.cols());
  holed.setFromTriplets(entries.begin(), entries.end());
  holed.makeCompressed();
  EXPECT_FALSE(node_pattern(holed));
  // Not 3 dofs per node.
  SparseMatrix odd(4, 4);
  odd.setIdentity();
  odd.makeCompressed();
  EXPECT_FALSE(node_pattern(odd));
}

TEST(BandCholesky, OrdersAFemHessiansNodes) {
  // The bar's nodes renumbered at random (each node's dofs kept together): ordering the node
  // pattern finds a band as narrow as the natural slice-by-slice numbering's.
  const SparseMatrix H = bar_hessian();
  const int n = static_cast<int>(H.rows());
  std::vector<int> node_shuffle(n / 3);
  for (int i = 0; i < n / 3; ++i) node_shuffle[i] = i;
  std::shuffle(node_shuffle.begin(), node_shuffle.end(), std::mt19937(11));
  const std::vector<int> shuffle = dof_order(node_shuffle);
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(n);
  for (int i = 0; i < n; ++i) P.indices()[i] = shuffle[i];
  SparseMatrix full_shuffled;
  full_shuffled = H.selfadjointView<Eigen::Lower>().twistedBy(P);
  const SparseMatrix shuffled = full_shuffled.triangularView<Eigen::Lower>();
  ASSERT_TRUE(node_pattern(shuffled));
  std::vector<int> identity(n);
  for (int i = 0; i < n; ++i) identity[i] = i;
  ASSERT_GT(bandwidth(shuffled, identity), n / 2);
  BandCholesky band;
  band.analyze(shuffled);
  EXPECT_LE(band.bandwidth(), bandwidth(H, identity));
  // And it solves: the band factor of the shuffled matrix against LDLᵀ's.
  ASSERT_TRUE(band.factorize(shuffled));
  SparseCholesky ldlt(Backend::SimplicialLDLT);
  ldlt.analyze(shuffled);
  ASSERT_TRUE(ldlt.factorize(shuffled));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 1);
  EXPECT_LT((band.solve(b).col(0) - ldlt.solve(b)).norm(), 1e-9 * ldlt.solve(b).norm());
}

}  // namespace
}  // namespace shapectl
