#pragma once
// Compressible neo-Hookean elasticity on linear tetrahedra (paper eq. 2):
// Ψ(F) = μ/2 (tr(FᵀF) − 3) − μ ln J + κ/2 (ln J)², J = det F, energy = Σ rest volume · Ψ.
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/fem/gradient_gather.hpp>
#include <shapectl/fem/material.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// Energy of one tet at corner positions x = [x0 x1 x2 x3]; +inf when J <= 0 (then gradient
// and Hessian are left untouched) so no line search accepts an inverted state.
// `project_psd` clamps the negative eigenvalues of ∂²Ψ/∂F² so the Hessian is PSD.
double neo_hookean_tet(const TetRest& rest, const Material& m, const Vec12& x,
                       Vec12* gradient = nullptr, Mat12* hessian = nullptr,
                       bool project_psd = false);

class NeoHookean : public EnergyTerm {
 public:
  // The mesh must outlive this.
  NeoHookean(const TetMesh& mesh, const Material& material);
  // Each element's own material: `materials` has one per element in mesh.tets() order, or a
  // single one for all (std::invalid_argument otherwise). Densities are not used here.
  NeoHookean(const TetMesh& mesh, std::vector<Material> materials);
  std::string_view name() const override { return "neo_hookean"; }
  double value(const Positions& x) const override;
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  double value_and_add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  void hessian_elements(const Positions& x, ElementNodes& elements) const override;
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const override;
  // One material for all elements, or one per element.
  const std::vector<Material>& materials() const { return materials_; }

 private:
  double tet_energy_and_gradient(const Positions& x, std::size_t e, double* corners) const;

  // Element e's material: materials_[0] for all, or materials_[e]. Indexed with a stride of 0 or
  // 1, not a branch, so the single-material hot loops stay as they were.
  const Material& material(std::size_t e) const { return materials_[stride_ * e]; }

  const TetMesh& mesh_;
  std::vector<Material> materials_;
  std::size_t stride_ = 0;
  GradientGather gather_;  // the tets' corners, node by node
};

}  // namespace shapectl
