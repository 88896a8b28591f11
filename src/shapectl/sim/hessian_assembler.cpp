#include <shapectl/sim/hessian_assembler.hpp>

#include <algorithm>

namespace shapectl {

HessianAssembler::HessianAssembler(int dof_count, std::vector<char> fixed_dof)
    : dof_count_(dof_count), fixed_dof_(std::move(fixed_dof)) {}

void HessianAssembler::build_pattern(const Triplets& triplets) {
  Triplets structure;
  structure.reserve(triplets.size() / 2 + dof_count_);
  for (int d = 0; d < dof_count_; ++d) structure.emplace_back(d, d, 0.0);
  for (const auto& t : triplets)
    if (t.row() >= t.col() && !fixed_dof_[t.row()] && !fixed_dof_[t.col()])
      structure.emplace_back(t.row(), t.col(), 0.0);
  matrix_.resize(dof_count_, dof_count_);
  matrix_.setFromTriplets(structure.begin(), structure.end());
  matrix_.makeCompressed();

  auto find_slot = [&](int row, int col) {
    const int* begin = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col];
    const int* end = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - matrix_.innerIndexPtr());
  };
  slot_.resize(triplets.size());
  for (std::size_t k = 0; k < triplets.size(); ++k) {
    const auto& t = triplets[k];
    const bool kept = t.row() >= t.col() && !fixed_dof_[t.row()] && !fixed_dof_[t.col()];
    slot_[k] = kept ? find_slot(t.row(), t.col()) : -1;
  }
  diagonal_slot_.resize(dof_count_);
  for (int d = 0; d < dof_count_; ++d) diagonal_slot_[d] = find_slot(d, d);
}

const SparseMatrix& HessianAssembler::assemble(const Triplets& triplets) {
  pattern_changed_ = slot_.size() != triplets.size();
  if (pattern_changed_) build_pattern(triplets);
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  for (std::size_t k = 0; k < triplets.size(); ++k)
    if (slot_[k] >= 0) values[slot_[k]] += triplets[k].value();
  for (int d = 0; d < dof_count_; ++d)
    if (fixed_dof_[d]) values[diagonal_slot_[d]] = 1.0;
  return matrix_;
}

}  // namespace shapectl
