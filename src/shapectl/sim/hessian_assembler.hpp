#pragma once
// Sums the energy terms' Hessians into a sparse matrix whose pattern is built once: the first
// call learns each term's elements and where each entry of their blocks lands (HessianScatter);
// later calls, with the same elements, only compute the blocks (on all cores) and add them into
// the matrix values. Keeps the lower triangle (what the Cholesky solvers read). Fixed degrees
// of freedom are eliminated: their rows and columns are dropped and their diagonal is 1.
#include <optional>
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/fem/hessian_scatter.hpp>

namespace shapectl {

class HessianAssembler {
 public:
  HessianAssembler(int dof_count, std::vector<char> fixed_dof);
  // ∂²E/∂x² of the sum of `terms` at x (size dof_count); `project_psd` makes each element block
  // positive semi-definite. A new pattern is built when the terms' elements are new.
  const SparseMatrix& assemble(const std::vector<const EnergyTerm*>& terms, const Positions& x,
                               bool project_psd);
  // How many patterns were built: a Cholesky analysed at another count must analyse again (a
  // flag for the last call alone would be lost to a later call with the same elements).
  int pattern_version() const { return pattern_version_; }
  // Builds the pattern and scatter map of the terms' elements at x, if they are new (assemble()
  // does); the matrix's values at x are then to be assembled. Returns pattern_version().
  int learn_pattern(const std::vector<const EnergyTerm*>& terms, const Positions& x);
  // assemble() without asking the terms for their elements again: for a caller that has just
  // called learn_pattern(terms, x) at the same x (asking is a pass over every element, compared
  // with the last).
  const SparseMatrix& assemble_values(const std::vector<const EnergyTerm*>& terms,
                                      const Positions& x, bool project_psd);
  // The node pattern of the matrix (HessianScatter::node_pattern), for fill-reducing orders.
  const SparseMatrix& node_pattern() const { return scatter_->node_pattern(); }
  // The matrix the last assemble() returned.
  const SparseMatrix& matrix() const { return matrix_; }
  const std::vector<char>& fixed_dof() const { return fixed_dof_; }

 private:
  int dof_count_;
  std::vector<char> fixed_dof_;
  SparseMatrix matrix_;
  std::vector<ElementNodes> elements_;  // each term's elements the scatter map was built for
  std::vector<ElementNodes> asked_;     // this call's, compared with elements_
  std::optional<HessianScatter> scatter_;
  int pattern_version_ = 0;
};

}  // namespace shapectl
