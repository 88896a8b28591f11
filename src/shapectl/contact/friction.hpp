#pragma once
// Smoothed, lagged Coulomb friction against static obstacles (IPC, Li et al. 2020, Sec. 5):
//   D(x) = Σₖ μ λₖ f₀(|uₖ|),   uₖ = Pₖ Σₐ wₐ (xₐ − x̄ₐ),
// over the contact pairs k of a lag state (ObstacleContact::pairs): λₖ their normal force,
// Pₖ = I − nₖnₖᵀ the projection off their normal, wₐ the closest-point weights of their object
// nodes, all frozen at the lag state; x̄ the anchor, the state tangential motion counts from (the
// obstacles do not move, so the pair's relative motion is the object's alone). f₀ smooths the
// kink of μλ|u| over the slip length ε:
//   f₀(y) = −y³/(3ε²) + y²/ε + ε/3 for y < ε,  y beyond  (C², f₀′ = f₁ ∈ [0, 1]).
// A pair resists up to μλ: below it the contact sticks (slips less than ε), at it slides.
// D is convex in x (f₀ convex and increasing, u linear): each pair's Hessian is PSD as it
// stands, in closed form. Its force's change through the lag itself (the lagged solve's fixed
// point, for exact sensitivities): friction_lag.hpp.
//
// The Hessian's elements are the contact's (the surface's vertices, edges, triangles), so the
// assembler's pattern stays that of the barrier whatever pairs are lagged.
#include <vector>

#include <shapectl/contact/obstacle_contact.hpp>

namespace shapectl {

// f₀(y) and f₁(y)/y for the slip length ε (f₁/y is finite at y = 0: 2/ε).
double friction_mollifier(double y, double slip);
double friction_mollifier_slope_over_y(double y, double slip);

class ObstacleFriction : public EnergyTerm {
 public:
  // `pairs` (of `contact`, at the lag state) resist with μ = coefficient; tangential motion
  // counts from `anchor`. slip ε > 0, m.
  ObstacleFriction(const ObstacleContact& contact, std::vector<ContactPair> pairs, Positions anchor,
                   double coefficient, double slip);

  std::string_view name() const override { return "friction"; }
  double value(const Positions& x) const override;
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  void hessian_elements(const Positions& x, ElementNodes& elements) const override;
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const override;

  // Pair k's tangential slip uₖ at x (world, m).
  Vec3 slip(const Positions& x, std::size_t k) const;
  const std::vector<ContactPair>& pairs() const { return pairs_; }
  double coefficient() const { return coefficient_; }
  double slip_length() const { return slip_; }

 private:
  ElementNodes elements_;           // the contact's
  std::vector<ContactPair> pairs_;  // sorted by element
  std::vector<int> first_;          // pairs of element e: first_[e] … first_[e + 1] − 1
  Positions anchor_;
  double coefficient_, slip_;
};

}  // namespace shapectl
