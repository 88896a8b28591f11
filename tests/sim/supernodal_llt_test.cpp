#include <shapectl/sim/supernodal_llt.hpp>

#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <limits>
#include <random>
#include <stdexcept>

#include <shapectl/types.hpp>

namespace shapectl {
namespace {

// A sparse symmetric positive definite matrix (lower triangle): a random pattern of about
// `per_column` entries a column, strictly diagonally dominant.
SparseMatrix random_spd(int n, int per_column, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> row(0, n - 1);
  std::uniform_real_distribution<double> value(-1, 1);
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < per_column; ++k) {
      const int i = row(rng);
      if (i <= j) continue;
      const double v = value(rng);
      entries.emplace_back(i, j, v);
      row_sums[i] += std::abs(v);
      row_sums[j] += std::abs(v);
    }
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, row_sums[i] + 1);
  SparseMatrix lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  return lower;
}

// CHOLMOD's factor of `lower`, supernodal or simplicial, in its natural order.
class Factor {
 public:
  Factor(const SparseMatrix& lower, bool supernodal) : lower_(lower) {
    cholmod_start(&common_);
    common_.print = 0;
    common_.supernodal = supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    common_.final_asis = 1;
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_NATURAL;
    common_.postorder = 0;
    const SparseMatrix& kept = lower_;
    cholmod_sparse a = Eigen::viewAsCholmod(kept.selfadjointView<Eigen::Lower>());
    factor_ = cholmod_analyze(&a, &common_);
    EXPECT_TRUE(factor_ && cholmod_factorize(&a, factor_, &common_));
  }
  ~Factor() {
    cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  cholmod_factor& operator*() const { return *factor_; }
  void* values() const { return factor_->x; }
  std::size_t value_count() const { return factor_->xsize; }

 private:
  SparseMatrix lower_;
  cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
};

// Solves with CHOLMOD's factor, then again after factoring with our own kernels.
void expect_solves(const SparseMatrix& lower, const char* what) {
  const Eigen::MatrixXd full = SparseMatrix(lower.selfadjointView<Eigen::Lower>());
  Factor factor(lower, true);
  for (const bool ours : {false, true}) {
    SCOPED_TRACE(ours ? "our factor" : "CHOLMOD's factor");
    if (ours) {
      std::fill_n(static_cast<double*>(factor.values()), factor.value_count(), 0.0);
      ASSERT_TRUE(factorize_supernodal(lower, *factor));
    }
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(lower.rows(), -1, 2);
    const Eigen::VectorXd expected = full.llt().solve(x);
    solve_supernodal_in_place(*factor, x);
    EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm()) << what;
    Eigen::MatrixXd X = Eigen::MatrixXd::Random(lower.rows(), 5);
    const Eigen::MatrixXd expected_many = full.llt().solve(X);
    solve_supernodal_in_place(*factor, X);
    EXPECT_LT((X - expected_many).norm(), 1e-12 * expected_many.norm()) << what;
  }
}

TEST(SupernodalLlt, FactorsAndSolvesAsADenseLltForOneAndManyRightHandSides) {
  // Many supernodes of all sizes, with rows below them (a random pattern fills in).
  const SparseMatrix sparse = random_spd(300, 3, 7);
  expect_solves(sparse, "random sparse");
  // Supernodes with no rows below: a diagonal matrix.
  const Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(40, 1, 5);
  expect_solves(SparseMatrix(Eigen::MatrixXd(d.asDiagonal()).sparseView()), "diagonal");
  // One supernode: a dense matrix.
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(30, 30);
  const Eigen::MatrixXd dense = a * a.transpose() + 30 * Eigen::MatrixXd::Identity(30, 30);
  expect_solves(SparseMatrix(dense.triangularView<Eigen::Lower>().toDenseMatrix().sparseView()),
                "dense");
}

TEST(SupernodalLlt, FactorsNoMatrixThatIsNotPositiveDefiniteOrFinite) {
  const SparseMatrix lower = random_spd(200, 3, 9);
  const Factor factor(lower, true);
  ASSERT_TRUE(factorize_supernodal(lower, *factor));
  SparseMatrix indefinite = lower;
  indefinite.coeffRef(150, 150) = -1;  // a pivot late in the order
  EXPECT_FALSE(factorize_supernodal(indefinite, *factor));
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    SparseMatrix not_finite = lower;
    not_finite.valuePtr()[not_finite.outerIndexPtr()[10] + 1] = bad;  // below the diagonal
    EXPECT_FALSE(factorize_supernodal(not_finite, *factor)) << bad;
  }
}

TEST(SupernodalLlt, RefusesASimplicialFactorOrAnotherSize) {
  const SparseMatrix lower = random_spd(50, 3, 8);
  Eigen::VectorXd x = Eigen::VectorXd::Ones(50);
  EXPECT_THROW(solve_supernodal_in_place(*Factor(lower, false), x), std::logic_error);
  Eigen::VectorXd wrong = Eigen::VectorXd::Ones(49);
  EXPECT_THROW(solve_supernodal_in_place(*Factor(lower, true), wrong), std::logic_error);
}

}  // namespace
}  // namespace shapectl
