#include <shapectl/linalg/band_cholesky.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <shapectl/hand_off.hpp>
#include <shapectl/linalg/band_factor.hpp>
#include <shapectl/linalg/node_pattern.hpp>
#include <shapectl/linalg/own_kernel_calls.hpp>

extern "C" {  // LAPACK and BLAS (OpenBLAS)
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab,
             const int* ldab, double* b, const int* ldb, int* info);
void stbsv_(const char* uplo, const char* trans, const char* diag, const int* n, const int* k,
            const float* a, const int* lda, float* x, const int* incx);
void dtrsm_(const char* side, const char* uplo, const char* trans, const char* diag, const int* m,
            const int* n, const double* alpha, const double* a, const int* lda, double* b,
            const int* ldb);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
            const double* beta, double* c, const int* ldc);
}

namespace shapectl {

namespace {
using Graph = std::vector<std::vector<int>>;

Graph adjacency(const SparseMatrix& lower) {
  Graph g(lower.rows());
  for (int j = 0; j < lower.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(lower, j); it; ++it)
      if (it.row() != j) {
        g[it.row()].push_back(j);
        g[j].push_back(it.row());
      }
  return g;
}

// Breadth-first search from `root` over vertices not yet done, neighbours taken by increasing
// degree as Cuthill–McKee prescribes.
struct Levels {
  std::vector<int> order;  // visiting order
  std::vector<int> last;   // the deepest level's vertices
  int depth = 0;
};

Levels bfs(const Graph& g, int root, const std::vector<char>& done) {
  Levels l;
  std::vector<int> level_of(g.size(), -1);
  l.order.push_back(root);
  level_of[root] = 0;
  for (std::size_t k = 0; k < l.order.size(); ++k) {
    std::vector<int> next;
    for (int v : g[l.order[k]])
      if (!done[v] && level_of[v] < 0) {
        level_of[v] = level_of[l.order[k]] + 1;
        next.push_back(v);
      }
    std::sort(next.begin(), next.end(), [&](int a, int b) { return g[a].size() < g[b].size(); });
    l.order.insert(l.order.end(), next.begin(), next.end());
  }
  l.depth = level_of[l.order.back()];
  for (int v : l.order)
    if (level_of[v] == l.depth) l.last.push_back(v);
  return l;
}

// George–Liu: move to a vertex of least degree in the deepest level while the depth grows.
int pseudo_peripheral(const Graph& g, int start, const std::vector<char>& done) {
  Levels from = bfs(g, start, done);
  for (int root = start;;) {
    const int candidate = *std::min_element(from.last.begin(), from.last.end(), [&](int a, int b) {
      return g[a].size() < g[b].size();
    });
    Levels next = bfs(g, candidate, done);
    if (next.depth <= from.depth) return root;
    root = candidate;
    from = std::move(next);
  }
}
}  // namespace

std::vector<int> reverse_cuthill_mckee(const SparseMatrix& lower) {
  const Graph g = adjacency(lower);
  const int n = static_cast<int>(g.size());
  std::vector<int> by_degree(n);
  for (int i = 0; i < n; ++i) by_degree[i] = i;
  std::stable_sort(by_degree.begin(), by_degree.end(),
                   [&](int a, int b) { return g[a].size() < g[b].size(); });
  std::vector<char> done(n, 0);
  std::vector<int> order;
  order.reserve(n);
  for (int start : by_degree) {
    if (done[start]) continue;
    if (g[start].empty()) {  // an isolated unknown (e.g. a fixed dof): no search needed
      done[start] = 1;
      order.push_back(start);
      continue;
    }
    const std::vector<int> part = bfs(g, pseudo_peripheral(g, start, done), done).order;
    for (int v : part) done[v] = 1;
    order.insert(order.end(), part.begin(), part.end());
  }
  std::reverse(order.begin(), order.end());
  return order;
}

namespace {
// Level-3 solve with the band factor, block column by block column. In LAPACK's lower band
// storage (ldab = kd + 1) L(r, c) sits at ab[r + c·kd]: a dense column-major matrix with
// leading dimension kd wherever the band covers the block (c ≤ r ≤ c + kd). A block column
// of `size` ≤ kd columns starting at j then splits into
//   the diagonal block    rows j .. j+size-1          (lower triangular, dtrsm),
//   a rectangle           rows j+size .. j+kd         (inside the band, dgemm in place),
//   a corner              rows j+kd+1 .. j+size-1+kd  (upper triangular: its lower part lies
//                         outside the band, so it is copied out with zeros there).
// Each block of L is read once per sweep for all right-hand sides, where dpbtrs streams the
// whole band twice per right-hand side (level-2 dtbsv).
class BandBlocks {
 public:
  BandBlocks(const double* ab, int n, int kd, int block) : ab_(ab), n_(n), kd_(kd), block_(block) {}
  int count() const { return (n_ + block_ - 1) / block_; }

  // Block column k: its diagonal block and rectangle in place, the corner's extent.
  struct Column {
    int first = 0, size = 0;
    const double* diagonal = nullptr;
    const double* rectangle = nullptr;
    int rectangle_rows = 0;  // from row first + size
    int corner_rows = 0;     // from row first + kd + 1, columns first + 1 .. first + size - 1
  };
  Column column(int k) const {
    Column c;
    c.first = k * block_;
    c.size = std::min(block_, n_ - c.first);
    c.diagonal = at(c.first, c.first);
    c.rectangle = at(c.first + c.size, c.first);
    c.rectangle_rows = std::min(c.first + kd_, n_ - 1) - (c.first + c.size) + 1;
    c.corner_rows = std::min(c.size - 1, n_ - 1 - c.first - kd_);
    return c;
  }
  // The corner, corner_rows × (size − 1), zero below its diagonal. Copied after the rectangle
  // was read: it ends the same columns of the band, so it is in cache by then.
  void copy_corner(const Column& c, std::vector<double>& corner) const {
    corner.assign(static_cast<std::size_t>(c.corner_rows) * (c.size - 1), 0.0);
    for (int col = 0; col < c.size - 1; ++col)
      for (int i = 0; i < c.corner_rows && i <= col; ++i)
        corner[i + static_cast<std::size_t>(col) * c.corner_rows] =
            *at(c.first + kd_ + 1 + i, c.first + 1 + col);
  }
  int leading() const { return kd_; }

 private:
  const double* at(int row, int col) const {
    return ab_ + row + static_cast<std::size_t>(col) * kd_;
  }
  const double* ab_;
  int n_, kd_, block_;
};

// Solves L Lᵀ X = B in place; B is n × columns, column-major.
void blocked_band_solve(const BandBlocks& blocks, int n, double* b, int columns) {
  const double one = 1, minus_one = -1;
  const int ld = blocks.leading();
  std::vector<double> corner;
  for (int k = 0; k < blocks.count(); ++k) {  // L Y = B
    const BandBlocks::Column c = blocks.column(k);
    double* y = b + c.first;
    dtrsm_("L", "L", "N", "N", &c.size, &columns, &one, c.diagonal, &ld, y, &n);
    if (c.rectangle_rows > 0)
      dgemm_("N", "N", &c.rectangle_rows, &columns, &c.size, &minus_one, c.rectangle, &ld, y, &n,
             &one, y + c.size, &n);
    if (c.corner_rows > 0) {
      blocks.copy_corner(c, corner);
      const int width = c.size - 1;
      dgemm_("N", "N", &c.corner_rows, &columns, &width, &minus_one, corner.data(), &c.corner_rows,
             y + 1, &n, &one, y + ld + 1, &n);
    }
  }
  for (int k = blocks.count() - 1; k >= 0; --k) {  // Lᵀ X = Y
    const BandBlocks::Column c = blocks.column(k);
    double* x = b + c.first;
    if (c.rectangle_rows > 0)
      dgemm_("T", "N", &c.size, &columns, &c.rectangle_rows, &minus_one, c.rectangle, &ld,
             x + c.size, &n, &one, x, &n);
    if (c.corner_rows > 0) {
      blocks.copy_corner(c, corner);
      const int width = c.size - 1;
      dgemm_("T", "N", &width, &columns, &c.corner_rows, &minus_one, corner.data(), &c.corner_rows,
             x + ld + 1, &n, &one, x + 1, &n);
    }
    dtrsm_("L", "L", "T", "N", &c.size, &columns, &one, c.diagonal, &ld, x, &n);
  }
}
}  // namespace

void BandCholesky::analyze(const SparseMatrix& lower) {
  const std::optional<SparseMatrix> nodes = node_pattern(lower);
  analyze(lower, nodes ? &*nodes : nullptr);
}

void BandCholesky::analyze(const SparseMatrix& lower, const SparseMatrix* nodes) {
  size_ = static_cast<int>(lower.rows());
  // On a FEM Hessian, the ordering of its nodes: the same band at a ninth of the work.
  const std::vector<int> order =
      nodes ? dof_order(reverse_cuthill_mckee(*nodes)) : reverse_cuthill_mckee(lower);
  new_index_.assign(size_, 0);
  for (int k = 0; k < size_; ++k) new_index_[order[k]] = k;
  bandwidth_ = 0;
  for (int j = 0; j < lower.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(lower, j); it; ++it)
      bandwidth_ = std::max(bandwidth_, std::abs(new_index_[it.row()] - new_index_[j]));
  const int rows = bandwidth_ + 1;
  slot_.clear();
  slot_.reserve(lower.nonZeros());
  for (int j = 0; j < lower.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(lower, j); it; ++it) {
      const int a = new_index_[it.row()], b = new_index_[j];
      slot_.push_back(std::abs(a - b) + std::min(a, b) * rows);
    }
  band_.resize(0);
}

double BandCholesky::flops() const {
  double f = 0;
  for (int j = 0; j < size_; ++j) {
    const double column = std::min(bandwidth_, size_ - 1 - j) + 1;
    f += column * column;
  }
  return f;
}

namespace {
constexpr int kOwnFactorFrom = 192;  // sub-diagonals
constexpr int kOwnFactorBlock = 32;  // columns per block column

// Pieces of the band that both cores fill (zero, round): the band is tens of MB at 12k tets,
// and its first filling also takes the page faults of fresh memory (~1.5 µs a 4 KiB page on
// the 2-core VM of docs/benchmarks.md), which two threads take in half the time.
tbb::blocked_range<Eigen::Index> band_pieces(Eigen::Index size) {
  return {0, size, Eigen::Index{1} << 16};
}
}  // namespace

bool BandCholesky::factorize(const SparseMatrix& lower) {
  count_own_kernel_call();
  band_single_current_ = false;
  band_.resize(static_cast<Eigen::Index>(bandwidth_ + 1) * size_);  // uninitialised
  HandOff zeroing;
  tbb::parallel_for(band_pieces(band_.size()), zeroing([&](const auto& piece) {
                      band_.segment(piece.begin(), piece.size()).setZero();
                    }));
  zeroing.joined();
  const double* values = lower.valuePtr();
  for (std::size_t k = 0; k < slot_.size(); ++k) band_[slot_[k]] += values[k];
  const int rows = bandwidth_ + 1;
  // Narrow bands: LAPACK's dpbtrf (one thread; its rank-32 updates are as fast as ours there).
  // Wider ones: our blocked factorization, its trailing updates split over two threads with a
  // look-ahead (band_factor.hpp). Crossover and block measured, docs/benchmarks.md.
  if (bandwidth_ >= kOwnFactorFrom) {
    if (!factor_band(band_.data(), size_, bandwidth_, kOwnFactorBlock, /*two_threads=*/true))
      return false;
  } else {
    int info = 0;
    dpbtrf_("L", &size_, &bandwidth_, band_.data(), &rows, &info);
    if (info != 0) return false;
  }
  // As for LDLᵀ: a pivot (L_jj²) tiny next to the largest means singular in double precision.
  double smallest = INFINITY, largest = 0;
  for (int j = 0; j < size_; ++j) {
    const double pivot =
        band_[static_cast<std::size_t>(j) * rows] * band_[static_cast<std::size_t>(j) * rows];
    smallest = std::min(smallest, pivot);
    largest = std::max(largest, pivot);
  }
  return smallest > 1e-13 * largest;
}

Eigen::VectorXd BandCholesky::solve_single_precision(const Eigen::VectorXd& rhs) const {
  count_own_kernel_call();
  // Subnormal floats are slow on most CPUs: entries of L a factor 1e-15 below its largest
  // (fill far from the diagonal decays) are dropped, and the right-hand side is scaled to 1.
  // Both change the result by far less than single precision's rounding.
  if (!band_single_current_) {
    HandOff largest_entry;
    const double largest = tbb::parallel_reduce(
        band_pieces(band_.size()), 0.0, largest_entry([&](const auto& piece, double m) {
          return std::max(m, band_.segment(piece.begin(), piece.size()).cwiseAbs().maxCoeff());
        }),
        largest_entry([](double a, double b) { return std::max(a, b); }));
    largest_entry.joined();
    const double negligible = 1e-15 * largest;
    band_single_.resize(band_.size());
    HandOff rounding;
    tbb::parallel_for(band_pieces(band_.size()), rounding([&](const auto& piece) {
                        for (Eigen::Index k = piece.begin(); k != piece.end(); ++k)
                          band_single_[k] =
                              std::abs(band_[k]) < negligible ? 0.0f : static_cast<float>(band_[k]);
                      }));
    rounding.joined();
    band_single_current_ = true;
  }
  const double scale = rhs.size() > 0 ? rhs.cwiseAbs().maxCoeff() : 0.0;
  if (scale == 0) return Eigen::VectorXd::Zero(size_);
  if (!std::isfinite(scale)) return solve(rhs).col(0);  // non-finite in, non-finite out
  std::vector<float> x(size_);
  for (int i = 0; i < size_; ++i) x[new_index_[i]] = static_cast<float>(rhs[i] / scale);
  const int rows = bandwidth_ + 1, step = 1;
  stbsv_("L", "N", "N", &size_, &bandwidth_, band_single_.data(), &rows, x.data(), &step);
  stbsv_("L", "T", "N", &size_, &bandwidth_, band_single_.data(), &rows, x.data(), &step);
  Eigen::VectorXd result(size_);
  for (int i = 0; i < size_; ++i) result[i] = scale * x[new_index_[i]];
  return result;
}

Eigen::MatrixXd BandCholesky::solve(const Eigen::MatrixXd& rhs) const {
  count_own_kernel_call();
  const int columns = static_cast<int>(rhs.cols());
  // Column by column, contiguously: along a row of a tall column-major matrix consecutive
  // elements are ~64 kB apart at 12k tets.
  Eigen::MatrixXd permuted(size_, columns);
  for (int k = 0; k < columns; ++k)
    for (int i = 0; i < size_; ++i) permuted(new_index_[i], k) = rhs(i, k);
  // The blocked solve from full blocks on and from three columns on: one or two columns are
  // as fast or faster with dpbtrs (piece/solve{1,2,4}_auto in bench/statics_bench.cpp).
  constexpr int kBlock = 32;  // columns of L per block, as in dpbtrf
  constexpr int kBlockedFromColumns = 3;
  if (bandwidth_ >= kBlock && columns >= kBlockedFromColumns) {
    blocked_band_solve(BandBlocks(band_.data(), size_, bandwidth_, kBlock), size_, permuted.data(),
                       columns);
  } else if (size_ > 0 && columns > 0) {
    const int rows = bandwidth_ + 1;
    int info = 0;
    dpbtrs_("L", &size_, &bandwidth_, &columns, band_.data(), &rows, permuted.data(), &size_,
            &info);
  }
  Eigen::MatrixXd result(size_, columns);
  for (int k = 0; k < columns; ++k)
    for (int i = 0; i < size_; ++i) result(i, k) = permuted(new_index_[i], k);
  return result;
}

}  // namespace shapectl
