#pragma once
// One additive part of the total energy E(x) of the object.
#include <string_view>

#include <shapectl/types.hpp>

namespace shapectl {

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string_view name() const = 0;
  // Energy at stacked positions x (size 3n), J; +inf where x is not admissible (inversion).
  virtual double value(const Positions& x) const = 0;
  // Adds ∂E/∂x to `gradient` (size 3n).
  virtual void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const = 0;
  // Appends ∂²E/∂x² as triplets, the same count in the same order on every call, so an
  // assembler can cache where each lands. `project_psd` makes each element block positive
  // semi-definite (the fallback when the true Hessian cannot be factorized).
  virtual void add_hessian(const Positions& x, Triplets& hessian, bool project_psd) const = 0;
};

}  // namespace shapectl
