#pragma once
// Sums Hessian triplets into a sparse matrix whose pattern is built once: the first call finds
// where each triplet lands, later calls (same triplets in the same order) only add values.
// Keeps the lower triangle (what the Cholesky solvers read). Fixed degrees of freedom are
// eliminated: their rows and columns are dropped and their diagonal is 1.
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

class HessianAssembler {
 public:
  HessianAssembler(int dof_count, std::vector<char> fixed_dof);
  // Returns the assembled matrix; `pattern_changed()` tells if the sparsity pattern is new.
  const SparseMatrix& assemble(const Triplets& triplets);
  bool pattern_changed() const { return pattern_changed_; }
  // The matrix the last assemble() returned.
  const SparseMatrix& matrix() const { return matrix_; }
  const std::vector<char>& fixed_dof() const { return fixed_dof_; }

 private:
  void build_pattern(const Triplets& triplets);
  int dof_count_;
  std::vector<char> fixed_dof_;
  SparseMatrix matrix_;
  std::vector<int> slot_;           // value index for each triplet, −1 if dropped
  std::vector<int> diagonal_slot_;  // value index of each diagonal entry
  bool pattern_changed_ = false;
};

}  // namespace shapectl
