#pragma once
// Gravitational potential E_g = −Σ mᵢ g·xᵢ (paper eq. 3) with lumped nodal masses: each tet
// gives a quarter of its mass to each corner. For a constant body force this equals the
// consistent linear-element load.
#include <shapectl/fem/energy_term.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// Lumped nodal masses (kg), size n; isolated nodes get 0.
Eigen::VectorXd lumped_masses(const TetMesh& mesh, double density);

class Gravity : public EnergyTerm {
 public:
  // g: gravitational acceleration in the world frame, m/s^2 (e.g. (0, 0, −9.81)).
  Gravity(const TetMesh& mesh, double density, const Vec3& g);
  std::string_view name() const override { return "gravity"; }
  double value(const Positions& x) const override { return x.dot(gradient_); }
  void add_gradient(const Positions&, Eigen::VectorXd& gradient) const override {
    gradient += gradient_;
  }
  // Linear in x: no Hessian, no elements.
  void hessian_elements(ElementNodes&) const override {}
  void add_hessian(const Positions&, ElementHessianSink&, bool) const override {}
  // Total weight of the object, N.
  double weight() const { return weight_; }

 private:
  Eigen::VectorXd gradient_;  // constant: −mᵢ g stacked
  double weight_ = 0;
};

}  // namespace shapectl
