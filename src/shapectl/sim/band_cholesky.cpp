#include <shapectl/sim/band_cholesky.hpp>

#include <algorithm>
#include <cmath>

extern "C" {  // LAPACK (OpenBLAS)
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab,
             const int* ldab, double* b, const int* ldb, int* info);
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

void BandCholesky::analyze(const SparseMatrix& lower) {
  size_ = static_cast<int>(lower.rows());
  const std::vector<int> order = reverse_cuthill_mckee(lower);
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
  band_.clear();
}

double BandCholesky::flops() const {
  double f = 0;
  for (int j = 0; j < size_; ++j) {
    const double column = std::min(bandwidth_, size_ - 1 - j) + 1;
    f += column * column;
  }
  return f;
}

bool BandCholesky::factorize(const SparseMatrix& lower) {
  band_.assign(static_cast<std::size_t>(bandwidth_ + 1) * size_, 0.0);
  const double* values = lower.valuePtr();
  for (std::size_t k = 0; k < slot_.size(); ++k) band_[slot_[k]] += values[k];
  const int rows = bandwidth_ + 1;
  int info = 0;
  dpbtrf_("L", &size_, &bandwidth_, band_.data(), &rows, &info);
  if (info != 0) return false;
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

Eigen::MatrixXd BandCholesky::solve(const Eigen::MatrixXd& rhs) const {
  const int columns = static_cast<int>(rhs.cols());
  Eigen::MatrixXd permuted(size_, columns);
  for (int i = 0; i < size_; ++i) permuted.row(new_index_[i]) = rhs.row(i);
  const int rows = bandwidth_ + 1;
  int info = 0;
  dpbtrs_("L", &size_, &bandwidth_, &columns, band_.data(), &rows, permuted.data(), &size_, &info);
  Eigen::MatrixXd result(size_, columns);
  for (int i = 0; i < size_; ++i) result.row(i) = permuted.row(new_index_[i]);
  return result;
}

}  // namespace shapectl
