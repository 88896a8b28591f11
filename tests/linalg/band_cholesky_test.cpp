#include <shapectl/linalg/band_cholesky.hpp>

#include <gtest/gtest.h>

#include <shapectl/linalg/band_factor.hpp>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

extern "C" void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab,
                        int* info);

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
// and above one block and two, sizes not a multiple of a block, ill-conditioned ones; and
// from 192 sub-diagonals on the blocked two-thread factorization (band_factor.hpp).
const Case kCases[] = {{1, 0},
                       {9, 0},
                       {9, 1},
                       {50, 1, 1e-6, true},
                       {12, 11},
                       {130, 129},
                       {200, 31},
                       {200, 32, 1e-3, true},
                       {97, 33},
                       {300, 63},
                       {300, 64},
                       {301, 65, 1e-2, true},
                       {257, 100},
                       {400, 150, 1e-4, true},
                       {100, 70},
                       {150, 140},
                       {521, 260, 1e-3, true}};
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

// The blocked factorization (band_factor.hpp) directly on LAPACK band storage.
std::vector<double> to_band(const Eigen::MatrixXd& a, int kd) {
  const int n = static_cast<int>(a.rows());
  std::vector<double> ab(static_cast<std::size_t>(kd + 1) * n, 0.0);
  for (int c = 0; c < n; ++c)
    for (int r = c; r <= std::min(n - 1, c + kd); ++r) ab[(r - c) + c * (kd + 1)] = a(r, c);
  return ab;
}

Eigen::MatrixXd from_band(const std::vector<double>& ab, int n, int kd) {
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (int c = 0; c < n; ++c)
    for (int r = c; r <= std::min(n - 1, c + kd); ++r) l(r, c) = ab[(r - c) + c * (kd + 1)];
  return l;
}

Eigen::MatrixXd dense_band_spd(int n, int kd, double margin, bool stiff, std::mt19937& rng) {
  return SparseMatrix(random_band_spd(n, kd, margin, stiff, rng).selfadjointView<Eigen::Lower>());
}

// γ_m = mε / (1 − mε): the relative rounding of a dot product of length m (Higham, ch. 3).
double gamma(int m) {
  const double u = std::numeric_limits<double>::epsilon() / 2;
  return m * u / (1 - m * u);
}

// Every bandwidth from 0 to n − 1, n smaller than a block, equal to one, not a multiple of
// one; blocks of 1 column up to wider than the band; one thread and two. The factor L must
// (a) reproduce A to Cholesky's backward error, |A − L Lᵀ| ≤ γ |L| |Lᵀ| entrywise, γ = γ_{kd+2}
// (Higham, Thm 10.3, with dot products of length kd + 1), and (b) equal the dense LLᵀ's and
// dpbtrf's factors within the perturbation bound for two backward-stable factors: ‖ΔL‖_F ≤ √2 κ₂ γ
// ‖L‖_F² ‖L‖₂ / ‖A‖₂ (Sun's first-order bound ‖ΔL‖_F ≤ κ₂ ‖ΔA‖_F ‖L‖₂ / (√2 ‖A‖₂) for each, with
// ‖ΔA‖_F ≤ γ ‖L‖_F²).
TEST(FactorBand, MatchesDenseCholeskyAndDpbtrfForEveryBandwidthBlockAndThreadCount) {
  std::mt19937 rng(2026);
  int compared = 0;
  for (const int n : {1, 2, 7, 37, 96, 130})
    for (int kd = 0; kd < n; kd += (n > 40 ? 3 : 1)) {
      const Eigen::MatrixXd a = dense_band_spd(n, kd, 0.5, kd % 2 == 0, rng);
      const Eigen::MatrixXd dense = a.llt().matrixL();
      std::vector<double> reference = to_band(a, kd);
      const int ldab = kd + 1;
      int info = 0;
      dpbtrf_("L", &n, &kd, reference.data(), &ldab, &info);
      ASSERT_EQ(info, 0);
      const double kappa = condition_number(a);
      const double g = gamma(kd + 2);
      const double norm_l = dense.norm();
      const double factor_tolerance = std::sqrt(2.0) * kappa * g * norm_l * norm_l *
                                      std::sqrt(a.operatorNorm()) / a.operatorNorm();
      for (const int block : {1, 3, 8, 32, 64, 200})
        for (const bool two_threads : {false, true}) {
          std::vector<double> ab = to_band(a, kd);
          ASSERT_TRUE(factor_band(ab.data(), n, kd, block, two_threads));
          const Eigen::MatrixXd l = from_band(ab, n, kd);
          // Twice: the test's own product L Lᵀ rounds as much again.
          const Eigen::MatrixXd bound = 2 * g * l.cwiseAbs() * l.cwiseAbs().transpose();
          const Eigen::MatrixXd residual = (a - l * l.transpose()).cwiseAbs();
          EXPECT_TRUE((residual.array() <= bound.array()).all())
              << "n " << n << " kd " << kd << " block " << block << " threads " << two_threads;
          EXPECT_LE((l - dense).norm(), factor_tolerance) << n << " " << kd << " " << block;
          EXPECT_LE((l - from_band(reference, n, kd)).norm(), factor_tolerance)
              << n << " " << kd << " " << block;
          ++compared;
        }
    }
  EXPECT_GT(compared, 1000);
}

// Not positive definite: false, whether the first diagonal block or a late one fails, with one
// thread and two. A late failure is the indefinite Hessian near buckling; failing early (at
// its block, not after a full factorization) is what lets the caller fall back quickly.
TEST(FactorBand, RefusesAnIndefiniteMatrixAtTheBlockThatFails) {
  std::mt19937 rng(3);
  const int n = 300, kd = 90;
  for (const int bad : {0, 150, n - 1})
    for (const bool two_threads : {false, true}) {
      Eigen::MatrixXd a = dense_band_spd(n, kd, 1, false, rng);
      a(bad, bad) = -1;
      std::vector<double> ab = to_band(a, kd);
      EXPECT_FALSE(factor_band(ab.data(), n, kd, 64, two_threads)) << bad;
      // Columns of blocks after the failing one are left as they were: nothing ran past it.
      const int untouched_from = (bad / 64 + 1) * 64 + kd;
      for (int c = untouched_from; c < n; ++c) EXPECT_EQ(ab[c * (kd + 1)], a(c, c)) << c;
    }
}

// Through BandCholesky, with bands wide enough for the blocked factorization and its
// threads: an indefinite matrix and a singular one (a stiffness-like matrix with nothing
// held: rows summing to zero, the constant vector in its null space) are refused.
TEST(BandCholesky, RefusesIndefiniteAndSingularWideBands) {
  std::mt19937 rng(5);
  for (const int kd : {40, 130, 300}) {
    const int n = 3 * kd + 17;
    const SparseMatrix spd = random_band_spd(n, kd, 1, false, rng);
    BandCholesky band;
    band.analyze(spd);
    ASSERT_TRUE(band.factorize(spd)) << kd;
    SparseMatrix indefinite = spd;
    indefinite.coeffRef(n - 5, n - 5) = -1;
    EXPECT_FALSE(band.factorize(indefinite)) << kd;
    const SparseMatrix singular = random_band_spd(n, kd, 0, true, rng);
    EXPECT_FALSE(band.factorize(singular)) << kd;
    EXPECT_TRUE(band.factorize(spd)) << kd;  // and it recovers
  }
}

}  // namespace
}  // namespace shapectl
