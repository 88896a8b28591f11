#include <shapectl/linalg/supernodal_llt.hpp>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/CholmodSupport>
#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>

#include <shapectl/linalg/serial_openmp.hpp>
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

// CHOLMOD's factor of `lower`, supernodal or simplicial, in its natural order; numeric, or its
// symbolic analysis alone. CHOLMOD on one thread, as the library runs it (SerialOpenMp): its
// fixed four OpenMP threads would also flood the TSan tests with reports on libgomp's memsets.
class Factor {
 public:
  Factor(const SparseMatrix& lower, bool supernodal, bool numeric = true) : lower_(lower) {
    SerialOpenMp one_thread;
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
    EXPECT_TRUE(factor_ && (!numeric || cholmod_factorize(&a, factor_, &common_)));
  }
  ~Factor() {
    SerialOpenMp one_thread;
    cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  cholmod_factor& operator*() const { return *factor_; }
  const SupernodalPattern& pattern() {
    if (pattern_.count() == 0) pattern_ = supernodal_pattern(*factor_);
    return pattern_;
  }
  double* values() const { return static_cast<double*>(factor_->x); }
  std::size_t value_count() const { return factor_->xsize; }

 private:
  SparseMatrix lower_;
  cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
  SupernodalPattern pattern_;
};

// Solves with CHOLMOD's factor, then again after factoring with our own kernels.
void expect_solves(const SparseMatrix& lower, const char* what) {
  const Eigen::MatrixXd full = SparseMatrix(lower.selfadjointView<Eigen::Lower>());
  Factor factor(lower, true);
  for (const bool ours : {false, true}) {
    SCOPED_TRACE(ours ? "our factor" : "CHOLMOD's factor");
    const SupernodalPattern& pattern = factor.pattern();
    if (ours) {
      std::fill_n(factor.values(), factor.value_count(), 0.0);
      ASSERT_TRUE(factorize_supernodal(lower, pattern, supernodal_teams(pattern), factor.values()));
    }
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(lower.rows(), -1, 2);
    const Eigen::VectorXd expected = full.llt().solve(x);
    solve_supernodal_in_place(pattern, factor.values(), x);
    EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm()) << what;
    Eigen::MatrixXd X = Eigen::MatrixXd::Random(lower.rows(), 5);
    const Eigen::MatrixXd expected_many = full.llt().solve(X);
    solve_supernodal_in_place(pattern, factor.values(), X);
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

// The 7-point Laplacian of a cells³ grid plus the identity, in CHOLMOD's fill-reducing order
// (AMD): an elimination tree with wide branches.
SparseMatrix ordered_grid_laplacian(int cells) {
  const int n = cells * cells * cells;
  auto index = [&](int i, int j, int k) { return (k * cells + j) * cells + i; };
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < cells; ++k)
    for (int j = 0; j < cells; ++j)
      for (int i = 0; i < cells; ++i) {
        entries.emplace_back(index(i, j, k), index(i, j, k), 7.0);
        if (i > 0) entries.emplace_back(index(i, j, k), index(i - 1, j, k), -1.0);
        if (j > 0) entries.emplace_back(index(i, j, k), index(i, j - 1, k), -1.0);
        if (k > 0) entries.emplace_back(index(i, j, k), index(i, j, k - 1), -1.0);
      }
  SparseMatrix lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  SerialOpenMp one_thread;
  cholmod_common common;
  cholmod_start(&common);
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  const SparseMatrix& view = lower;
  cholmod_sparse a = Eigen::viewAsCholmod(view.selfadjointView<Eigen::Lower>());
  cholmod_factor* symbolic = cholmod_analyze(&a, &common);
  const int* order = static_cast<const int*>(symbolic->Perm);
  Eigen::VectorXi position(n);
  for (int p = 0; p < n; ++p) position[order[p]] = p;
  cholmod_free_factor(&symbolic, &common);
  cholmod_finish(&common);
  for (auto& e : entries) {
    const int r = position[e.row()], c = position[e.col()];
    e = Eigen::Triplet<double>(std::max(r, c), std::min(r, c), e.value());
  }
  SparseMatrix ordered(n, n);
  ordered.setFromTriplets(entries.begin(), entries.end());
  return ordered;
}

TEST(SupernodalLlt, FactorsTwoSubtreesAtOnceAsCholmodDoesInOne) {
  const SparseMatrix lower = ordered_grid_laplacian(18);
  Factor factor(lower, true);  // by CHOLMOD
  const SupernodalPattern& pattern = factor.pattern();
  const std::vector<int> teams = supernodal_teams(pattern);
  EXPECT_EQ(supernodal_teams(Factor(lower, true, false).pattern()), teams)
      << "from the analysis alone";
  for (const int team : {0, 1, 2})
    EXPECT_GT(std::count(teams.begin(), teams.end(), team), 0) << "no supernode in team " << team;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(lower.rows(), -1, 2);
  Eigen::VectorXd by_cholmod = b, by_ours = b;
  solve_supernodal_in_place(pattern, factor.values(), by_cholmod);
  std::fill_n(factor.values(), factor.value_count(), 0.0);
  ASSERT_TRUE(factorize_supernodal(lower, pattern, teams, factor.values()));
  solve_supernodal_in_place(pattern, factor.values(), by_ours);
  EXPECT_LT((by_ours - by_cholmod).norm(), 1e-12 * by_cholmod.norm());
  const Eigen::VectorXd residual = lower.selfadjointView<Eigen::Lower>() * by_ours - b;
  EXPECT_LT(residual.norm(), 1e-12 * b.norm());
  // A pivot that fails in either subtree, or above them, fails the factorization.
  for (const int team : {0, 1, 2}) {
    const int k = static_cast<int>(std::find(teams.begin(), teams.end(), team) - teams.begin());
    const int column = pattern.first_column[k];
    SparseMatrix indefinite = lower;
    indefinite.coeffRef(column, column) = -1;
    EXPECT_FALSE(factorize_supernodal(indefinite, pattern, teams, factor.values()))
        << "team " << team;
  }
}

TEST(SupernodalLlt, SolvesTwoSubtreesAtOnceAsInOne) {
  // The teams' solve: the two subtrees on two threads, the rows above both collected from each
  // and added after. It must give the one-thread solve's answer, one and many right-hand sides.
  const SparseMatrix lower = ordered_grid_laplacian(18);
  Factor factor(lower, true);
  const SupernodalPattern& pattern = factor.pattern();
  const std::vector<int> teams = supernodal_teams(pattern);
  ASSERT_GT(std::count(teams.begin(), teams.end(), 1), 0);
  ASSERT_GT(std::count(teams.begin(), teams.end(), 2), 0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(lower.rows(), -1, 2);
  {
    SCOPED_TRACE("CHOLMOD's factor");
    Eigen::VectorXd one_thread = b, two = b;
    solve_supernodal_in_place(pattern, factor.values(), one_thread);
    solve_supernodal_in_place(pattern, factor.values(), two, teams);
    EXPECT_LT((two - one_thread).norm(), 1e-13 * one_thread.norm());
  }
  ASSERT_TRUE(factorize_supernodal(lower, pattern, teams, factor.values()));
  Eigen::VectorXd one_thread = b, two = b;
  solve_supernodal_in_place(pattern, factor.values(), one_thread);
  solve_supernodal_in_place(pattern, factor.values(), two, teams);
  EXPECT_LT((two - one_thread).norm(), 1e-13 * one_thread.norm());
  EXPECT_LT((lower.selfadjointView<Eigen::Lower>() * two - b).norm(), 1e-12 * b.norm());
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(lower.rows(), 4);
  Eigen::MatrixXd many_one_thread = B, many_two = B;
  solve_supernodal_in_place(pattern, factor.values(), many_one_thread);
  solve_supernodal_in_place(pattern, factor.values(), many_two, teams);
  EXPECT_LT((many_two - many_one_thread).norm(), 1e-13 * many_one_thread.norm());
}

TEST(SupernodalLlt, FactorsNoMatrixThatIsNotPositiveDefiniteOrFinite) {
  const SparseMatrix lower = random_spd(200, 3, 9);
  Factor factor(lower, true);
  const SupernodalPattern& pattern = factor.pattern();
  const std::vector<int> teams = supernodal_teams(pattern);
  ASSERT_TRUE(factorize_supernodal(lower, pattern, teams, factor.values()));
  SparseMatrix indefinite = lower;
  indefinite.coeffRef(150, 150) = -1;  // a pivot late in the order
  EXPECT_FALSE(factorize_supernodal(indefinite, pattern, teams, factor.values()));
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    SparseMatrix not_finite = lower;
    not_finite.valuePtr()[not_finite.outerIndexPtr()[10] + 1] = bad;  // below the diagonal
    EXPECT_FALSE(factorize_supernodal(not_finite, pattern, teams, factor.values())) << bad;
  }
}

TEST(SupernodalLlt, RefusesASimplicialFactorAnotherSizeOrNoValues) {
  const SparseMatrix lower = random_spd(50, 3, 8);
  EXPECT_THROW(supernodal_pattern(*Factor(lower, false)), std::logic_error);
  Factor factor(lower, true);
  const SupernodalPattern& pattern = factor.pattern();
  Eigen::VectorXd wrong = Eigen::VectorXd::Ones(49);
  EXPECT_THROW(solve_supernodal_in_place(pattern, factor.values(), wrong), std::logic_error);
  Eigen::VectorXd x = Eigen::VectorXd::Ones(50);
  EXPECT_THROW(solve_supernodal_in_place(pattern, nullptr, x), std::logic_error);
  std::vector<int> too_few = supernodal_teams(pattern);
  too_few.pop_back();
  EXPECT_THROW(factorize_supernodal(lower, pattern, too_few, factor.values()), std::logic_error);
  EXPECT_THROW(solve_supernodal_in_place(pattern, factor.values(), x, too_few), std::logic_error);
  const SparseMatrix smaller = random_spd(49, 3, 8);
  EXPECT_THROW(factorize_supernodal(smaller, pattern, supernodal_teams(pattern), factor.values()),
               std::logic_error);
}

}  // namespace
}  // namespace shapectl
