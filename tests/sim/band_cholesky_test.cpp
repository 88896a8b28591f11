#include <shapectl/sim/band_cholesky.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>

namespace shapectl {
namespace {

// A random SPD matrix with every entry of its band (|i - j| ≤ bandwidth) set, lower triangle,
// diagonally dominant by `margin` over the row's off-diagonal sum. Off-diagonals of random
// sign, or with `stiff` all negative (like a stiffness matrix, a Laplacian): then a small
// margin (a body held only weakly) makes it ill-conditioned, κ ~ 1/margin.
SparseMatrix random_band_spd(int n, int bandwidth, double margin, bool stiff, std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i <= std::min(n - 1, j + bandwidth); ++i)
      a(i, j) = a(j, i) = stiff ? -std::abs(uniform(rng)) : uniform(rng);
  for (int i = 0; i < n; ++i) a(i, i) = a.row(i).cwiseAbs().sum() + margin;
  const SparseMatrix full = a.sparseView();
  return full.triangularView<Eigen::Lower>();
}

double condition_number(const Eigen::MatrixXd& a) {
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues();
  return eigenvalues.maxCoeff() / eigenvalues.minCoeff();
}

struct Case {
  int size, bandwidth;
  double margin = 1;
  bool stiff = false;
};

// Sizes and bandwidths around the solve's blocking (blocks of 32 columns, the blocked solve
// from 32 sub-diagonals and 3 right-hand sides on, LAPACK's dpbtrs below): diagonal,
// tridiagonal, dense (bandwidth n − 1) with one block and with several, bands just below, at
// and above one block and two, sizes not a multiple of a block, ill-conditioned ones.
const Case kCases[] = {{1, 0},     {9, 0},
                       {9, 1},     {50, 1, 1e-6, true},
                       {12, 11},   {130, 129},
                       {200, 31},  {200, 32, 1e-3, true},
                       {97, 33},   {300, 63},
                       {300, 64},  {301, 65, 1e-2, true},
                       {257, 100}, {400, 150, 1e-4, true},
                       {100, 70}};
const int kColumnCounts[] = {1, 2, 14, 37};

// Solving with the band factor gives the dense LLᵀ's solution to round-off. Both solves are
// backward stable: each is the exact solution for a matrix off by about γ = (3(b+1)+1)·ε
// relatively (b the bandwidth: the length of the dot products), so they differ by at most
// 2γ·κ relatively, κ the condition number.
TEST(BandCholesky, SolvesLikeADenseCholeskyForEveryBandwidthAndColumnCount) {
  std::mt19937 rng(14);
  for (const Case& c : kCases) {
    const SparseMatrix lower = random_band_spd(c.size, c.bandwidth, c.margin, c.stiff, rng);
    const Eigen::MatrixXd full = SparseMatrix(lower.selfadjointView<Eigen::Lower>());
    BandCholesky band;
    band.analyze(lower);
    ASSERT_TRUE(band.factorize(lower)) << c.size << " " << c.bandwidth;
    const double kappa = condition_number(full);
    const double tolerance =
        2 * (3 * (band.bandwidth() + 1) + 1) * std::numeric_limits<double>::epsilon() * kappa;
    for (int columns : kColumnCounts) {
      const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(c.size, columns);
      const Eigen::MatrixXd reference = full.llt().solve(rhs);
      const Eigen::MatrixXd x = band.solve(rhs);
      ASSERT_EQ(x.rows(), c.size);
      ASSERT_EQ(x.cols(), columns);
      for (int k = 0; k < columns; ++k) {
        ASSERT_GT(reference.col(k).norm(), 0);
        EXPECT_LE((x.col(k) - reference.col(k)).norm(), tolerance * reference.col(k).norm())
            << "n " << c.size << ", bandwidth " << band.bandwidth() << ", κ " << kappa << ", "
            << columns << " columns, column " << k;
      }
    }
  }
}

// The single-precision solve (chord and Krylov steps' preconditioner) is the same solve with
// float's ε: within the bound above with ε_float, doubled for rounding the factor itself to
// float. And it is single precision: off by more than double's bound somewhere.
TEST(BandCholesky, SinglePrecisionSolveIsWithinSinglePrecisionsBound) {
  std::mt19937 rng(21);
  int checked = 0;
  bool beyond_double = false;
  for (const Case& c : kCases) {
    const SparseMatrix lower = random_band_spd(c.size, c.bandwidth, c.margin, c.stiff, rng);
    const Eigen::MatrixXd full = SparseMatrix(lower.selfadjointView<Eigen::Lower>());
    BandCholesky band;
    band.analyze(lower);
    ASSERT_TRUE(band.factorize(lower));
    const double kappa = condition_number(full);
    const double dot_length = 3 * (band.bandwidth() + 1) + 1;
    const double tolerance = 4 * dot_length * std::numeric_limits<float>::epsilon() * kappa;
    if (tolerance > 0.1) continue;  // an ill-conditioned case says nothing at this precision
    const Eigen::VectorXd rhs = 1e-3 * Eigen::VectorXd::Random(c.size);  // scaled inside
    const Eigen::VectorXd reference = full.llt().solve(rhs);
    const Eigen::VectorXd x = band.solve_single_precision(rhs);
    const double error = (x - reference).norm() / reference.norm();
    EXPECT_LE(error, tolerance) << "n " << c.size << ", bandwidth " << c.bandwidth;
    beyond_double |= error > 2 * dot_length * std::numeric_limits<double>::epsilon() * kappa;
    ++checked;
    EXPECT_EQ(band.solve_single_precision(Eigen::VectorXd::Zero(c.size)),
              Eigen::VectorXd::Zero(c.size));
  }
  EXPECT_GE(checked, 8);
  EXPECT_TRUE(beyond_double);
}

// The cases cover what they claim: RCM keeps a full band's width (it cannot narrow it).
TEST(BandCholesky, TheTestBandsKeepTheirWidth) {
  std::mt19937 rng(14);
  for (const Case& c : kCases) {
    const SparseMatrix lower = random_band_spd(c.size, c.bandwidth, c.margin, c.stiff, rng);
    BandCholesky band;
    band.analyze(lower);
    EXPECT_EQ(band.bandwidth(), c.bandwidth) << c.size;
  }
}

// Many right-hand sides at once (the blocked level-3 solve) give what one at a time (LAPACK's
// dpbtrs) gives, to round-off: the same factor, the same bound as against the dense solve.
TEST(BandCholesky, ManyColumnsAtOnceMatchOneAtATime) {
  std::mt19937 rng(7);
  const SparseMatrix lower = random_band_spd(500, 120, 1e-2, true, rng);
  const Eigen::MatrixXd full = SparseMatrix(lower.selfadjointView<Eigen::Lower>());
  BandCholesky band;
  band.analyze(lower);
  ASSERT_TRUE(band.factorize(lower));
  const double tolerance = 2 * (3 * (band.bandwidth() + 1) + 1) *
                           std::numeric_limits<double>::epsilon() * condition_number(full);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(500, 37);
  const Eigen::MatrixXd together = band.solve(rhs);
  for (int k = 0; k < rhs.cols(); ++k) {
    const Eigen::MatrixXd alone = band.solve(rhs.col(k));
    EXPECT_LE((together.col(k) - alone.col(0)).norm(), tolerance * alone.norm()) << k;
  }
}

}  // namespace
}  // namespace shapectl
