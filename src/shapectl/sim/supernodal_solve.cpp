#include <shapectl/sim/supernodal_solve.hpp>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace shapectl {

namespace {

// Supernode k: columns first … first + columns − 1 of L, a dense column-major block of `rows`
// rows (the diagonal block, then the rows below it, whose indices are listed).
struct Supernode {
  int first, columns, rows;
  const double* values;
  const int* below_rows;  // the row indices under the diagonal block, rows − columns of them
};

class Supernodes {
 public:
  explicit Supernodes(const cholmod_factor& f)
      : super_(static_cast<const int*>(f.super)),
        row_starts_(static_cast<const int*>(f.pi)),
        value_starts_(static_cast<const int*>(f.px)),
        row_index_(static_cast<const int*>(f.s)),
        values_(static_cast<const double*>(f.x)),
        count_(static_cast<int>(f.nsuper)) {
    if (!f.is_super || !f.is_ll || f.xtype != CHOLMOD_REAL || f.itype != CHOLMOD_INT || !values_)
      throw std::logic_error("solve_supernodal_in_place: a numeric real supernodal LLᵀ factor");
  }
  int count() const { return count_; }
  Supernode operator[](int k) const {
    const int first = super_[k], columns = super_[k + 1] - first;
    return {first, columns, row_starts_[k + 1] - row_starts_[k], values_ + value_starts_[k],
            row_index_ + row_starts_[k] + columns};
  }
  int most_rows() const {
    int most = 0;
    for (int k = 0; k < count_; ++k) most = std::max(most, row_starts_[k + 1] - row_starts_[k]);
    return most;
  }

 private:
  const int *super_, *row_starts_, *value_starts_, *row_index_;
  const double* values_;
  int count_;
};

// Forward (L y = b, supernodes in order) then backward (Lᵀ x = y, in reverse). A supernode's
// rows below its diagonal block touch x only through gathers and scatters of those rows.
template <typename X>
void forward_backward(const cholmod_factor& factor, X& x) {
  const Supernodes supernodes(factor);
  if (x.rows() != static_cast<Eigen::Index>(factor.n))
    throw std::logic_error("solve_supernodal_in_place: as many rows as the factor");
  std::vector<double> work(static_cast<std::size_t>(supernodes.most_rows()) * x.cols());
  for (int k = 0; k < supernodes.count(); ++k) {
    const Supernode s = supernodes[k];
    const Eigen::Map<const Eigen::MatrixXd> block(s.values, s.rows, s.columns);
    auto diagonal = x.middleRows(s.first, s.columns);
    block.topRows(s.columns).template triangularView<Eigen::Lower>().solveInPlace(diagonal);
    const int below = s.rows - s.columns;
    if (below == 0) continue;
    Eigen::Map<Eigen::MatrixXd> update(work.data(), below, x.cols());
    update.noalias() = block.bottomRows(below) * diagonal;
    for (int i = 0; i < below; ++i) x.row(s.below_rows[i]) -= update.row(i);
  }
  for (int k = supernodes.count() - 1; k >= 0; --k) {
    const Supernode s = supernodes[k];
    const Eigen::Map<const Eigen::MatrixXd> block(s.values, s.rows, s.columns);
    auto diagonal = x.middleRows(s.first, s.columns);
    const int below = s.rows - s.columns;
    if (below > 0) {
      Eigen::Map<Eigen::MatrixXd> known(work.data(), below, x.cols());
      for (int i = 0; i < below; ++i) known.row(i) = x.row(s.below_rows[i]);
      diagonal.noalias() -= block.bottomRows(below).transpose() * known;
    }
    block.topRows(s.columns).transpose().template triangularView<Eigen::Upper>().solveInPlace(
        diagonal);
  }
}

}  // namespace

void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::VectorXd& x) {
  forward_backward(factor, x);
}

void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::MatrixXd& x) {
  forward_backward(factor, x);
}

}  // namespace shapectl
