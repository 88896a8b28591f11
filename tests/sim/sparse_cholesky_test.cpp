#include <shapectl/sim/sparse_cholesky.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/band_cholesky.hpp>
#include <shapectl/sim/object_statics.hpp>

namespace shapectl {
namespace {

using Backend = SparseCholesky::Backend;
const Backend kBackends[] = {Backend::SimplicialLDLT, Backend::Band, Backend::CholmodSupernodal};

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
  for (Backend backend : kBackends) {
    SparseCholesky cholesky(backend);
    cholesky.analyze(H);
    ASSERT_TRUE(cholesky.factorize(H)) << static_cast<int>(backend);
    const Eigen::MatrixXd y = cholesky.solve(rhs);
    EXPECT_LT((y - reference).norm(), 1e-9 * reference.norm()) << static_cast<int>(backend);
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
  for (Backend backend : kBackends) {
    SparseCholesky cholesky(backend);
    cholesky.analyze(indefinite);
    EXPECT_FALSE(cholesky.factorize(indefinite)) << static_cast<int>(backend);
    EXPECT_FALSE(cholesky.factorize(singular)) << static_cast<int>(backend);
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
  // Elongated or small meshes, and a block whose band is still narrow (~700 sub-diagonals,
  // 2.8x the sparse flops, measured 1.6x faster): the band.
  for (const auto& [size, cells] : {std::pair{Vec3(0.32, 0.03, 0.03), std::array{16, 4, 4}},
                                    std::pair{Vec3(0.08, 0.08, 0.08), std::array{8, 8, 8}},
                                    std::pair{Vec3(0.64, 0.12, 0.11), std::array{64, 12, 11}},
                                    std::pair{Vec3(0.14, 0.14, 0.14), std::array{14, 14, 14}}}) {
    SparseCholesky cholesky;
    cholesky.analyze(rest_hessian(clamped_box(size, cells)));
    EXPECT_EQ(cholesky.backend(), Backend::Band) << cells[0] << "x" << cells[1] << "x" << cells[2];
  }
  // A larger compact block: a band over 1,000 wide doing 3.7x the supernodal flops.
  SparseCholesky block;
  block.analyze(rest_hessian(clamped_box({0.2, 0.2, 0.2}, {20, 20, 20})));
  EXPECT_EQ(block.backend(), Backend::CholmodSupernodal);
}

TEST(SparseCholesky, StaticsReachesTheSameEquilibriumWithEveryBackend) {
  Scene scene = clamped_box({0.32, 0.03, 0.03}, {16, 4, 4});
  std::vector<Positions> results;
  for (Backend backend : kBackends) {
    scene.statics.backend = backend;
    ObjectStatics statics(scene);
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    ASSERT_TRUE(r.converged()) << r.reason;
    results.push_back(x);
  }
  for (std::size_t k = 1; k < results.size(); ++k)
    EXPECT_LT((results[k] - results[0]).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace shapectl
