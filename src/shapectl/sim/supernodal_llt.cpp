#include <shapectl/sim/supernodal_llt.hpp>

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>
#include <vector>

namespace shapectl {

namespace {

// Supernode k: columns first … first + columns − 1 of L, stored as a dense column-major block
// of `rows` rows: the diagonal block (rows first … first + columns − 1), then the rows below it.
struct Supernode {
  int first, columns, rows;
  double* values;
  const int* row_index;  // all `rows` of them, ascending
};

// CHOLMOD's supernodal factor, read through its arrays.
class Supernodes {
 public:
  explicit Supernodes(const cholmod_factor& f)
      : super_(static_cast<const int*>(f.super)),
        row_starts_(static_cast<const int*>(f.pi)),
        value_starts_(static_cast<const int*>(f.px)),
        row_index_(static_cast<const int*>(f.s)),
        values_(static_cast<double*>(f.x)),
        count_(static_cast<int>(f.nsuper)) {
    if (!f.is_super || !f.is_ll || f.xtype != CHOLMOD_REAL || f.itype != CHOLMOD_INT || !values_)
      throw std::logic_error("supernodal LLᵀ: a real supernodal factor with its values");
  }
  int count() const { return count_; }
  Supernode operator[](int k) const {
    return {super_[k], super_[k + 1] - super_[k], row_starts_[k + 1] - row_starts_[k],
            values_ + value_starts_[k], row_index_ + row_starts_[k]};
  }
  int most_rows() const { return most(row_starts_); }
  int most_columns() const { return most(super_); }

 private:
  int most(const int* starts) const {
    int result = 0;
    for (int k = 0; k < count_; ++k) result = std::max(result, starts[k + 1] - starts[k]);
    return result;
  }
  const int *super_, *row_starts_, *value_starts_, *row_index_;
  double* values_;
  int count_;
};

using Block = Eigen::Map<Eigen::MatrixXd>;
Block block_of(const Supernode& s) { return Block(s.values, s.rows, s.columns); }

// Forward (L y = b, supernodes in order) then backward (Lᵀ x = y, in reverse). A supernode's
// rows below its diagonal block touch x only through gathers and scatters of those rows.
template <typename X>
void forward_backward(const cholmod_factor& factor, X& x) {
  const Supernodes supernodes(factor);
  if (x.rows() != static_cast<Eigen::Index>(factor.n))
    throw std::logic_error("supernodal LLᵀ: solve as many rows as the factor has");
  std::vector<double> work(static_cast<std::size_t>(supernodes.most_rows()) * x.cols());
  for (int k = 0; k < supernodes.count(); ++k) {
    const Supernode s = supernodes[k];
    const Block block = block_of(s);
    auto diagonal = x.middleRows(s.first, s.columns);
    block.topRows(s.columns).template triangularView<Eigen::Lower>().solveInPlace(diagonal);
    const int below = s.rows - s.columns;
    if (below == 0) continue;
    Block update(work.data(), below, x.cols());
    update.noalias() = block.bottomRows(below) * diagonal;
    for (int i = 0; i < below; ++i) x.row(s.row_index[s.columns + i]) -= update.row(i);
  }
  for (int k = supernodes.count() - 1; k >= 0; --k) {
    const Supernode s = supernodes[k];
    const Block block = block_of(s);
    auto diagonal = x.middleRows(s.first, s.columns);
    const int below = s.rows - s.columns;
    if (below > 0) {
      Block known(work.data(), below, x.cols());
      for (int i = 0; i < below; ++i) known.row(i) = x.row(s.row_index[s.columns + i]);
      diagonal.noalias() -= block.bottomRows(below).transpose() * known;
    }
    block.topRows(s.columns).transpose().template triangularView<Eigen::Upper>().solveInPlace(
        diagonal);
  }
}

}  // namespace

bool factorize_supernodal(const SparseMatrix& lower, cholmod_factor& factor) {
  const Supernodes supernodes(factor);
  const int n = static_cast<int>(factor.n);
  if (lower.rows() != n || lower.cols() != n || !lower.isCompressed())
    throw std::logic_error("supernodal LLᵀ: factorize a compressed matrix of the factor's size");
  // Left-looking: supernode j first takes its columns of A, then the updates of every earlier
  // supernode d with rows in j's columns (its descendants), then factors itself. `waiting[j]`
  // lists those d (linked through next_waiting); once d has updated j it waits for the
  // supernode of its next row below j's columns, from `next_row[d]` on.
  std::vector<int> owner(n);  // column → its supernode
  for (int k = 0; k < supernodes.count(); ++k)
    for (int c = 0; c < supernodes[k].columns; ++c) owner[supernodes[k].first + c] = k;
  std::vector<int> waiting(supernodes.count(), -1), next_waiting(supernodes.count(), -1);
  std::vector<int> next_row(supernodes.count(), 0);
  auto wait_for_next_row = [&](int d, int position) {
    const Supernode s = supernodes[d];
    if (position == s.rows) return;
    next_row[d] = position;
    const int target = owner[s.row_index[position]];
    next_waiting[d] = waiting[target];
    waiting[target] = d;
  };
  std::vector<int> local_row(n);  // row → its place in the supernode being factored
  std::vector<double> work(static_cast<std::size_t>(supernodes.most_rows()) *
                           supernodes.most_columns());
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  const double* values = lower.valuePtr();
  for (int j = 0; j < supernodes.count(); ++j) {
    const Supernode s = supernodes[j];
    for (int i = 0; i < s.rows; ++i) local_row[s.row_index[i]] = i;
    Block block = block_of(s);
    block.setZero();
    for (int c = 0; c < s.columns; ++c)
      for (int k = outer[s.first + c]; k < outer[s.first + c + 1]; ++k)
        block(local_row[inner[k]], c) = values[k];
    const int end = s.first + s.columns;
    for (int d = waiting[j]; d != -1;) {
      const int next = next_waiting[d];
      const Supernode from = supernodes[d];
      // d's rows from `first` on: those up to `last` are j's columns, all are j's rows.
      const int first = next_row[d];
      int last = first;
      while (last < from.rows && from.row_index[last] < end) ++last;
      const int in_columns = last - first, in_rows = from.rows - first;
      const Block d_block = block_of(from);
      Block update(work.data(), in_rows, in_columns);
      update.noalias() =
          d_block.middleRows(first, in_rows) * d_block.middleRows(first, in_columns).transpose();
      for (int c = 0; c < in_columns; ++c) {
        double* column = &block(0, from.row_index[first + c] - s.first);
        for (int r = c; r < in_rows; ++r)
          column[local_row[from.row_index[first + r]]] -= update(r, c);
      }
      wait_for_next_row(d, last);
      d = next;
    }
    auto diagonal = block.topRows(s.columns);
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(diagonal);
    // LLT stops at a pivot ≤ 0 only; a NaN pivot passes it, and any non-finite entry of A
    // reaches some later pivot through the updates.
    if (llt.info() != Eigen::Success || !diagonal.diagonal().allFinite()) return false;
    if (s.rows == s.columns) continue;
    auto below = block.bottomRows(s.rows - s.columns);
    diagonal.transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(below);
    wait_for_next_row(j, s.columns);
  }
  return true;
}

void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::VectorXd& x) {
  forward_backward(factor, x);
}

void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::MatrixXd& x) {
  forward_backward(factor, x);
}

}  // namespace shapectl
