#include <shapectl/sim/hessian_assembler.hpp>

#include <algorithm>
#include <stdexcept>

namespace shapectl {

namespace {

// What one term's add_hessian writes to: its blocks go through the scatter map into the values.
class ScatterSink : public ElementHessianSink {
 public:
  ScatterSink(const HessianScatter& scatter, std::size_t term, double* values)
      : scatter_(scatter), term_(term), values_(values) {}
  void add_blocks(const ElementKernel& kernel) override {
    scatter_.add_blocks(term_, kernel, values_);
  }

 private:
  const HessianScatter& scatter_;
  std::size_t term_;
  double* values_;
};

}  // namespace

HessianAssembler::HessianAssembler(int dof_count, std::vector<char> fixed_dof)
    : dof_count_(dof_count), fixed_dof_(std::move(fixed_dof)) {}

int HessianAssembler::learn_pattern(const std::vector<const EnergyTerm*>& terms,
                                    const Positions& x) {
  asked_.resize(terms.size());
  for (std::size_t t = 0; t < terms.size(); ++t) {
    asked_[t].clear();
    terms[t]->hessian_elements(x, asked_[t]);
  }
  if (scatter_ && asked_ == elements_) return pattern_version_;
  std::swap(elements_, asked_);
  scatter_.emplace(dof_count_, fixed_dof_, elements_, matrix_);
  return ++pattern_version_;
}

const SparseMatrix& HessianAssembler::assemble(const std::vector<const EnergyTerm*>& terms,
                                               const Positions& x, bool project_psd) {
  learn_pattern(terms, x);
  return assemble_values(terms, x, project_psd);
}

const SparseMatrix& HessianAssembler::assemble_values(const std::vector<const EnergyTerm*>& terms,
                                                      const Positions& x, bool project_psd) {
  if (!scatter_ || terms.size() != elements_.size())
    throw std::logic_error("HessianAssembler: assemble_values before learn_pattern of the terms");
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  for (std::size_t t = 0; t < terms.size(); ++t) {
    ScatterSink sink(*scatter_, t, values);
    terms[t]->add_hessian(x, sink, project_psd);
  }
  for (const int slot : scatter_->fixed_diagonal_slots()) values[slot] = 1.0;
  return matrix_;
}

}  // namespace shapectl
