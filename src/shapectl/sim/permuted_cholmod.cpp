#include <shapectl/sim/permuted_cholmod.hpp>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <shapectl/sim/supernodal_llt.hpp>

namespace shapectl {

namespace {

cholmod_sparse lower_view(const SparseMatrix& lower) {
  return Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
}

void throw_if_failed(bool ok, const char* what) {
  if (!ok) throw std::runtime_error(std::string("CHOLMOD could not ") + what + " (out of memory?)");
}

}  // namespace

struct PermutedCholmod::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  SparseMatrix permuted;   // P A Pᵀ, lower triangle
  std::vector<int> slot;   // entry k of the analysed matrix's values goes to permuted's slot[k]
  std::vector<int> order;  // order[k]: the analysed matrix's row that is permuted's row k
  std::vector<int> teams;  // supernodal_teams of the analysis, for our kernels

  Impl() {
    cholmod_start(&common);
    common.print = 0;  // not positive definite is an expected outcome, not something to print
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.final_asis = 1;  // keep the supernodal LLᵀ as it is made
  }
  ~Impl() {
    free_factor();
    cholmod_finish(&common);
  }
  void free_factor() {
    if (factor) cholmod_free_factor(&factor, &common);
  }
  // CHOLMOD's own order for `lower`: its default strategy, followed by its postorder.
  std::vector<int> own_order(const SparseMatrix& lower) {
    common.nmethods = 0;
    common.postorder = 1;
    cholmod_sparse a = lower_view(lower);
    cholmod_factor* f = cholmod_analyze(&a, &common);
    throw_if_failed(f != nullptr, "order the Hessian");
    const int* perm = static_cast<const int*>(f->Perm);
    std::vector<int> result(perm, perm + f->n);
    cholmod_free_factor(&f, &common);
    return result;
  }
};

PermutedCholmod::PermutedCholmod(double own_kernels_below_flops)
    : impl_(std::make_unique<Impl>()), own_kernels_below_flops_(own_kernels_below_flops) {}
PermutedCholmod::~PermutedCholmod() = default;
PermutedCholmod::PermutedCholmod(PermutedCholmod&&) noexcept = default;
PermutedCholmod& PermutedCholmod::operator=(PermutedCholmod&&) noexcept = default;

void PermutedCholmod::analyze(const SparseMatrix& lower, std::vector<int> order) {
  Impl& m = *impl_;
  m.free_factor();
  if (order.empty()) order = m.own_order(lower);
  const int n = static_cast<int>(lower.rows());
  std::vector<int> position(n);
  for (int k = 0; k < n; ++k) position[order[k]] = k;

  // Entry (i, j) of the lower triangle lands at (max, min) of their positions. Two counting
  // passes place the entries column by column, rows ascending, without a comparison sort: first
  // by row, then, row by row in order, into their columns.
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  const int entries = static_cast<int>(lower.nonZeros());
  std::vector<int> row_starts(n + 1, 0), starts(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int a = position[inner[k]], b = position[j];
      ++row_starts[std::max(a, b) + 1];
      ++starts[std::min(a, b) + 1];
    }
  for (int r = 0; r < n; ++r) {
    row_starts[r + 1] += row_starts[r];
    starts[r + 1] += starts[r];
  }
  struct Landing {
    int column, entry;
  };
  std::vector<Landing> by_row(entries);
  std::vector<int> next(row_starts.begin(), row_starts.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int a = position[inner[k]], b = position[j];
      by_row[next[std::max(a, b)]++] = {std::min(a, b), k};
    }
  SparseMatrix& p = m.permuted;
  p.resize(n, n);
  p.makeCompressed();
  p.resizeNonZeros(entries);
  std::copy(starts.begin(), starts.end(), p.outerIndexPtr());
  m.slot.resize(entries);
  next.assign(starts.begin(), starts.end() - 1);
  for (int r = 0; r < n; ++r)
    for (int s = row_starts[r]; s < row_starts[r + 1]; ++s) {
      const int slot = next[by_row[s].column]++;
      p.innerIndexPtr()[slot] = r;
      m.slot[by_row[s].entry] = slot;
    }
  std::fill(p.valuePtr(), p.valuePtr() + starts[n], 0.0);
  m.order = std::move(order);

  // The natural order, and no postorder: it would reorder the matrix again.
  m.common.nmethods = 1;
  m.common.method[0].ordering = CHOLMOD_NATURAL;
  m.common.postorder = 0;
  // CHOLMOD's own supernode merging (nrelax, zrelax): with our kernels, which make no calls
  // per supernode, merging twice as far was 5-15 % slower (a TetGen frame and bar, a plate).
  cholmod_sparse a = lower_view(p);
  m.factor = cholmod_analyze(&a, &m.common);
  throw_if_failed(m.factor != nullptr, "analyse the Hessian");
  flops_ = m.common.fl;
  m.teams = own_kernels() ? supernodal_teams(*m.factor) : std::vector<int>();
}

bool PermutedCholmod::factorize(const SparseMatrix& lower) {
  Impl& m = *impl_;
  if (!m.factor || static_cast<std::size_t>(lower.nonZeros()) != m.slot.size())
    throw std::logic_error("PermutedCholmod: factorize a matrix of the analysed pattern");
  const double* from = lower.valuePtr();
  double* to = m.permuted.valuePtr();
  bool finite = true;  // CHOLMOD factors a matrix with a NaN "successfully"
  for (std::size_t k = 0; k < m.slot.size(); ++k) {
    to[m.slot[k]] = from[k];
    finite = finite && std::isfinite(from[k]);
  }
  if (!finite) return false;
  if (own_kernels()) {
    if (m.factor->xtype == CHOLMOD_PATTERN)
      throw_if_failed(cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, m.factor,
                                            &m.common),
                      "allocate its factor");
    return factorize_supernodal(m.permuted, *m.factor, m.teams);
  }
  cholmod_sparse a = lower_view(m.permuted);
  // On a matrix that is not positive definite CHOLMOD stops at column `minor` < n.
  return cholmod_factorize(&a, m.factor, &m.common) && m.factor->minor == m.factor->n;
}

namespace {

// Solves A x = rhs with the factor of P A Pᵀ: rhs gathered into the order, solved in place,
// scattered back.
template <typename Matrix>
Matrix solve_permuted(const cholmod_factor* factor, const std::vector<int>& order,
                      const Matrix& rhs) {
  if (!factor || factor->xtype == CHOLMOD_PATTERN)
    throw std::logic_error("PermutedCholmod: solve after a successful factorization");
  const Eigen::Index n = rhs.rows();
  Matrix y(n, rhs.cols());
  for (Eigen::Index k = 0; k < n; ++k) y.row(k) = rhs.row(order[k]);
  solve_supernodal_in_place(*factor, y);
  Matrix x(n, rhs.cols());
  for (Eigen::Index k = 0; k < n; ++k) x.row(order[k]) = y.row(k);
  return x;
}

}  // namespace

Eigen::MatrixXd PermutedCholmod::solve(const Eigen::MatrixXd& rhs) const {
  return solve_permuted(impl_->factor, impl_->order, rhs);
}

Eigen::VectorXd PermutedCholmod::solve(const Eigen::VectorXd& rhs) const {
  return solve_permuted(impl_->factor, impl_->order, rhs);
}

}  // namespace shapectl
