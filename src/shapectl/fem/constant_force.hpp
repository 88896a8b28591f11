#pragma once
// Constant nodal forces f (N): E = −Σ fᵢ·xᵢ, gradient −f, no Hessian. Gravity's weights and a
// scene's applied loads. Independent of the joints too, so sensitivities need nothing from it.
#include <shapectl/fem/energy_term.hpp>

namespace shapectl {

class ConstantForce : public EnergyTerm {
 public:
  // forces: stacked per node (size 3n), world frame, N. `name` must outlive this (a literal).
  ConstantForce(std::string_view name, const Eigen::VectorXd& forces)
      : name_(name), gradient_(-forces) {}
  std::string_view name() const override { return name_; }
  double value(const Positions& x) const override { return x.dot(gradient_); }
  void add_gradient(const Positions&, Eigen::VectorXd& gradient) const override {
    gradient += gradient_;
  }
  // Linear in x: no Hessian, no elements.
  void hessian_elements(const Positions&, ElementNodes&) const override {}
  void add_hessian(const Positions&, ElementHessianSink&, bool) const override {}
  // The forces f, stacked (3n), N.
  Eigen::VectorXd forces() const { return -gradient_; }

 private:
  std::string_view name_;
  Eigen::VectorXd gradient_;  // constant: −f
};

}  // namespace shapectl
