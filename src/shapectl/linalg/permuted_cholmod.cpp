#include <shapectl/linalg/permuted_cholmod.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <shapectl/linalg/cholmod_view.hpp>
#include <shapectl/linalg/node_pattern.hpp>
#include <shapectl/linalg/own_kernel_calls.hpp>
#include <shapectl/linalg/supernodal_llt.hpp>
#include <shapectl/linalg/supernodal_pattern.hpp>

namespace shapectl {

struct PermutedCholmod::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;  // CHOLMOD's, where its kernels factor
  SparseMatrix permuted;             // P A Pᵀ, lower triangle
  std::vector<int> slot;      // entry k of the analysed matrix's values goes to permuted's slot[k]
  std::vector<int> order;     // order[k]: the analysed matrix's row that is permuted's row k
  SupernodalPattern pattern;  // the factor's structure (our kernels', or CHOLMOD's copied)
  std::vector<int> teams;     // supernodal_teams of the pattern: our factorization and solves
  std::unique_ptr<double[]> values;  // our kernels' factor
  bool factored = false;             // by the last factorize()

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
  // CHOLMOD's analysis of `lower` with its default strategy (nmethods 0) or one ordering.
  cholmod_factor* analyse(const SparseMatrix& lower, int ordering, bool postorder) {
    common.nmethods = ordering < 0 ? 0 : 1;
    common.method[0].ordering = ordering < 0 ? CHOLMOD_AMD : ordering;
    common.postorder = postorder;
    cholmod_sparse a = cholmod_lower_view(lower);
    cholmod_factor* f = cholmod_analyze(&a, &common);
    throw_if_cholmod_failed(f != nullptr, "analyse the Hessian");
    return f;
  }
  const double* factor_values() const {
    return factor ? static_cast<const double*>(factor->x) : values.get();
  }
  void set_relaxation(const std::array<std::size_t, 3>& nrelax) {
    for (int k = 0; k < 3; ++k) common.nrelax[k] = nrelax[k];
  }
};

namespace {

// CHOLMOD's default supernode merging (nrelax: columns, with zrelax's fractions of zeros): with
// our kernels, which make no calls per supernode, merging twice as far was 5-15 % slower (a
// TetGen frame and bar, a plate). On the nodes, a third as many columns stand for the same.
constexpr std::array<std::size_t, 3> kDofRelaxation{4, 16, 48};
constexpr std::array<std::size_t, 3> kNodeRelaxation{1, 5, 16};

// The permutation's inverse: position[i] is where row i goes.
std::vector<int> positions(const std::vector<int>& order) {
  std::vector<int> position(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) position[order[k]] = static_cast<int>(k);
  return position;
}

// Where the entries of `lower` land in P lower Pᵀ: entry k = (i, j) at row max, column min of
// their positions, transposed where i's comes first. Listed row by row (by_row, rows from
// row_starts[r]) with each column's count (column_starts): two counting passes, no sort.
struct Landings {
  struct Landing {
    int column, entry;
    bool transposed;
  };
  std::vector<int> row_starts, column_starts;
  std::vector<Landing> by_row;
};
Landings land(const SparseMatrix& lower, const std::vector<int>& position) {
  const int n = static_cast<int>(lower.cols());
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  Landings l{std::vector<int>(n + 1, 0), std::vector<int>(n + 1, 0),
             std::vector<Landings::Landing>(lower.nonZeros())};
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int a = position[inner[k]], b = position[j];
      ++l.row_starts[std::max(a, b) + 1];
      ++l.column_starts[std::min(a, b) + 1];
    }
  for (int r = 0; r < n; ++r) {
    l.row_starts[r + 1] += l.row_starts[r];
    l.column_starts[r + 1] += l.column_starts[r];
  }
  std::vector<int> next(l.row_starts.begin(), l.row_starts.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int a = position[inner[k]], b = position[j];
      l.by_row[next[std::max(a, b)]++] = {std::min(a, b), k, a < b};
    }
  return l;
}

}  // namespace

PermutedCholmod::PermutedCholmod(double own_kernels_below_flops)
    : impl_(std::make_unique<Impl>()), own_kernels_below_flops_(own_kernels_below_flops) {}
PermutedCholmod::~PermutedCholmod() = default;
PermutedCholmod::PermutedCholmod(PermutedCholmod&&) noexcept = default;
PermutedCholmod& PermutedCholmod::operator=(PermutedCholmod&&) noexcept = default;

void PermutedCholmod::analyze(const SparseMatrix& lower, std::vector<int> order) {
  Impl& m = *impl_;
  m.free_factor();
  m.set_relaxation(kDofRelaxation);
  if (order.empty()) {
    cholmod_factor* f = m.analyse(lower, -1, true);
    const int* perm = static_cast<const int*>(f->Perm);
    order.assign(perm, perm + f->n);
    cholmod_free_factor(&f, &m.common);
  }
  const int n = static_cast<int>(lower.rows());
  const std::vector<int> position = positions(order);

  // The entries in the order, column by column, rows ascending: row by row into their columns.
  const Landings l = land(lower, position);
  const std::vector<int>& starts = l.column_starts;
  SparseMatrix& p = m.permuted;
  p.resize(n, n);
  p.makeCompressed();
  p.resizeNonZeros(lower.nonZeros());
  std::copy(starts.begin(), starts.end(), p.outerIndexPtr());
  m.slot.resize(lower.nonZeros());
  std::vector<int> next(starts.begin(), starts.end() - 1);
  for (int r = 0; r < n; ++r)
    for (int s = l.row_starts[r]; s < l.row_starts[r + 1]; ++s) {
      const int slot = next[l.by_row[s].column]++;
      p.innerIndexPtr()[slot] = r;
      m.slot[l.by_row[s].entry] = slot;
    }
  std::fill(p.valuePtr(), p.valuePtr() + starts[n], 0.0);
  m.order = std::move(order);
  m.factor = m.analyse(p, CHOLMOD_NATURAL, false);  // no postorder: it would reorder again
  m.pattern = supernodal_pattern(*m.factor);
  flops_ = m.common.fl;
  finish_analysis();
}

void PermutedCholmod::analyze_nodes(const SparseMatrix& lower, const SparseMatrix& nodes) {
  Impl& m = *impl_;
  m.free_factor();
  const int node_count = static_cast<int>(nodes.rows());
  if (lower.rows() != 3 * node_count || !lower.isCompressed() || !nodes.isCompressed())
    throw std::logic_error("PermutedCholmod: a matrix of 3n rows and its n-node pattern");

  // The nodes' order and factor structure: AMD, and METIS too where AMD's factor is dense, as
  // CHOLMOD's own rule says on the dofs (over 500 flops per entry of L and 5 entries of L per
  // entry of A). A node stands for 27 times its flops and 9 times its entries.
  m.set_relaxation(kNodeRelaxation);
  cholmod_factor* node_factor = m.analyse(nodes, CHOLMOD_AMD, true);
  if (3 * m.common.fl >= 500 * m.common.lnz && m.common.lnz >= 5 * nodes.nonZeros()) {
    const double amd_flops = m.common.fl;
    cholmod_factor* metis = m.analyse(nodes, CHOLMOD_METIS, true);
    if (m.common.fl < amd_flops) std::swap(node_factor, metis);
    cholmod_free_factor(&metis, &m.common);
  }
  const SupernodalPattern node_pattern = supernodal_pattern(*node_factor);
  const int* perm = static_cast<const int*>(node_factor->Perm);
  const std::vector<int> node_order(perm, perm + node_count);
  cholmod_free_factor(&node_factor, &m.common);
  const std::vector<int> node_position = positions(node_order);

  // The node pattern in the order: node entry q lands in a column as its `rank`-th row (0: the
  // diagonal); node_rows lists each column's rows, ascending.
  const Landings l = land(nodes, node_position);
  const std::vector<int>& column_starts = l.column_starts;
  struct NodeEntry {
    int column, rank;
    bool transposed;
  };
  std::vector<NodeEntry> landing(nodes.nonZeros());
  std::vector<int> rows_in(node_count, 0), node_rows(nodes.nonZeros());
  for (int r = 0; r < node_count; ++r)
    for (int s = l.row_starts[r]; s < l.row_starts[r + 1]; ++s) {
      const Landings::Landing& q = l.by_row[s];
      if (rows_in[q.column] == 0 && q.column != r)
        throw std::logic_error("PermutedCholmod: a node pattern with every diagonal");
      node_rows[column_starts[q.column] + rows_in[q.column]] = r;
      landing[q.entry] = {q.column, rows_in[q.column]++, q.transposed};
    }

  // The dofs in whole node blocks: column 3J + c of the gathered matrix holds node J's rows
  // from 3J + c on, then the three rows of each other node of node column J, ascending.
  const int n = 3 * node_count;
  SparseMatrix& p = m.permuted;
  p.resize(n, n);
  p.makeCompressed();
  int* outer = p.outerIndexPtr();
  outer[0] = 0;
  for (int J = 0; J < node_count; ++J)
    for (int c = 0; c < 3; ++c) outer[3 * J + c + 1] = outer[3 * J + c] + 3 * rows_in[J] - c;
  p.resizeNonZeros(outer[n]);
  int* inner = p.innerIndexPtr();
  for (int J = 0; J < node_count; ++J)
    for (int c = 0; c < 3; ++c) {
      int* to = inner + outer[3 * J + c];
      for (int t = column_starts[J]; t < column_starts[J + 1]; ++t)
        for (int r = t == column_starts[J] ? c : 0; r < 3; ++r) *to++ = 3 * node_rows[t] + r;
    }
  std::fill(p.valuePtr(), p.valuePtr() + outer[n], 0.0);  // held dofs' rows stay zero

  // Each entry's slot: entry (3i + r, 3j + c) of node entry q = (i, j) goes to row r of column
  // c of q's block (transposed: row c of column r).
  const int* node_outer = nodes.outerIndexPtr();
  const int* node_inner = nodes.innerIndexPtr();
  const int* a_outer = lower.outerIndexPtr();
  const int* a_inner = lower.innerIndexPtr();
  m.slot.resize(lower.nonZeros());
  for (int j = 0; j < node_count; ++j)
    for (int c = 0; c < 3; ++c) {
      int q = node_outer[j];
      for (int k = a_outer[3 * j + c]; k < a_outer[3 * j + c + 1]; ++k) {
        const int i = a_inner[k] / 3, r = a_inner[k] % 3;
        while (q < node_outer[j + 1] && node_inner[q] < i) ++q;
        if (q == node_outer[j + 1] || node_inner[q] != i)
          throw std::logic_error("PermutedCholmod: an entry outside the node pattern");
        const NodeEntry& e = landing[q];
        const int row = e.transposed ? c : r, column = e.transposed ? r : c;
        m.slot[k] = outer[3 * e.column + column] +
                    (e.rank == 0 ? row - column : 3 - column + 3 * (e.rank - 1) + row);
      }
    }
  m.order = dof_order(node_order);
  m.pattern = expand_blocks(node_pattern, 3);
  flops_ = m.pattern.flops();
  if (!own_kernels()) {
    m.set_relaxation(kDofRelaxation);
    m.factor = m.analyse(p, CHOLMOD_NATURAL, false);
    m.pattern = supernodal_pattern(*m.factor);
  }
  finish_analysis();
}

void PermutedCholmod::finish_analysis() {
  Impl& m = *impl_;
  m.teams = supernodal_teams(m.pattern);  // our solves use them with CHOLMOD's factor too
  if (own_kernels()) m.free_factor();     // its structure is copied into the pattern
  m.values.reset();
  m.factored = false;
}

bool PermutedCholmod::factorize(const SparseMatrix& lower) {
  count_own_kernel_call();  // the gather into our order, whoever factors
  Impl& m = *impl_;
  if (m.order.empty() || static_cast<std::size_t>(lower.nonZeros()) != m.slot.size())
    throw std::logic_error("PermutedCholmod: factorize a matrix of the analysed pattern");
  m.factored = false;
  const double* from = lower.valuePtr();
  double* to = m.permuted.valuePtr();
  bool finite = true;  // CHOLMOD factors a matrix with a NaN "successfully"
  for (std::size_t k = 0; k < m.slot.size(); ++k) {
    to[m.slot[k]] = from[k];
    finite = finite && std::isfinite(from[k]);
  }
  if (!finite) return false;
  if (own_kernels()) {
    if (!m.values) m.values.reset(new double[m.pattern.value_count()]);  // the kernels fill it
    m.factored = factorize_supernodal(m.permuted, m.pattern, m.teams, m.values.get());
    return m.factored;
  }
  cholmod_sparse a = cholmod_lower_view(m.permuted);
  // On a matrix that is not positive definite CHOLMOD stops at column `minor` < n.
  m.factored = cholmod_factorize(&a, m.factor, &m.common) && m.factor->minor == m.factor->n;
  return m.factored;
}

namespace {

// Solves A x = rhs with the factor of P A Pᵀ: rhs gathered into the order, solved in place,
// scattered back.
template <typename Matrix>
Matrix solve_permuted(const SupernodalPattern& pattern, const double* values,
                      const std::vector<int>& teams, const std::vector<int>& order,
                      const Matrix& rhs) {
  const Eigen::Index n = rhs.rows();
  if (n != static_cast<Eigen::Index>(order.size()))
    throw std::logic_error("PermutedCholmod: solve as many rows as the matrix has");
  Matrix y(n, rhs.cols());
  for (Eigen::Index k = 0; k < n; ++k) y.row(k) = rhs.row(order[k]);
  solve_supernodal_in_place(pattern, values, y, teams);
  Matrix x(n, rhs.cols());
  for (Eigen::Index k = 0; k < n; ++k) x.row(order[k]) = y.row(k);
  return x;
}

}  // namespace

Eigen::MatrixXd PermutedCholmod::solve(const Eigen::MatrixXd& rhs) const {
  const Impl& m = *impl_;
  if (!m.factored)
    throw std::logic_error("PermutedCholmod: solve after a successful factorization");
  return solve_permuted(m.pattern, m.factor_values(), m.teams, m.order, rhs);
}

Eigen::VectorXd PermutedCholmod::solve(const Eigen::VectorXd& rhs) const {
  const Impl& m = *impl_;
  if (!m.factored)
    throw std::logic_error("PermutedCholmod: solve after a successful factorization");
  return solve_permuted(m.pattern, m.factor_values(), m.teams, m.order, rhs);
}

}  // namespace shapectl
