#pragma once
// One additive part of the total energy E(x) of the object.
#include <string_view>

#include <shapectl/fem/element_hessians.hpp>
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
  // value(x), and add_gradient(x, gradient), in one call: the same numbers bit for bit. A term
  // overrides it where one pass over its elements can share the work (F, J, F⁻ᵀ per tet); the
  // default calls the two.
  virtual double value_and_add_gradient(const Positions& x, Eigen::VectorXd& gradient) const;
  // Appends the nodes of each element whose Hessian block add_hessian(x) gives at x. Most terms
  // give the same elements in the same order at every x, so an assembler can cache where each
  // block lands; a term whose elements follow x (self-contact: the pairs of its own surface
  // within reach) gives them as a function of x alone, and the assembler builds a new pattern
  // when they change.
  virtual void hessian_elements(const Positions& x, ElementNodes& elements) const = 0;
  // ∂²E/∂x² as one block per element (hessian_elements(x) order) through sink.add_blocks, called
  // once. `project_psd` makes each block positive semi-definite (the fallback when the true
  // Hessian cannot be factorized).
  virtual void add_hessian(const Positions& x, ElementHessianSink& sink,
                           bool project_psd) const = 0;
  // The largest step length α ∈ (0, 1] such that the whole way from x to x + α·dx stays
  // admissible for this term (contact: continuous collision detection, so no surface passes
  // through an obstacle between two iterates). Terms admissible everywhere: 1.
  virtual double max_step(const Positions& /*x*/, const Eigen::VectorXd& /*dx*/) const {
    return 1.0;
  }

  // The same Hessian as triplets (every entry of every block, both triangles); for tests and
  // tools that want a plain sparse matrix.
  Triplets hessian_triplets(const Positions& x, bool project_psd) const;
};

}  // namespace shapectl
