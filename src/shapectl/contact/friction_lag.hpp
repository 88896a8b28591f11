#pragma once
// How the lagged friction's force changes through its lag (friction.hpp). The lagged solve ends
// at a fixed point: x balances E plus D lagged at x itself (λ, n, w of the pairs at x), so its
// force balance is G(x) = ∇E(x) + ∇ₓD(x; lag(x)) and
//   ∂G/∂x = ∇²E + ∇²ₓD (lag fixed: ObstacleFriction::add_hessian) + L,
//   L = ∂/∂y ∇ₓD(x; lag(y)) at y = x,
// L not symmetric: a pair pressed harder (λ up) resists harder, and its tangent plane and
// closest point turn with n and w. Per pair, for its element's nodes a, c, with
// v = Σ_b w_b (x_b − x̄_b), u = P v, φ = μ f₁(|u|) u/|u| (the force per unit λ), Jφ = ∂φ/∂u:
//   L_ac = φ (λ ∂wₐ/∂x_c + wₐ ∂λ/∂x_c)
//        + wₐ λ Jφ [−n (vᵀ ∂n/∂x_c) − (n·v) ∂n/∂x_c + P Σ_b (x_b − x̄_b) ∂w_b/∂x_c].
// The anchor x̄ does not depend on x (nor on θ: it is the solve's warm start).
#include <vector>

#include <shapectl/contact/obstacle_contact.hpp>

namespace shapectl {

// L at x for friction μ = coefficient, slip length ε, lagged at x (its pairs with derivatives,
// ObstacleContact::pair_derivatives(x)), tangential motion from `anchor`: 3n × 3n triplets.
Triplets friction_lag_jacobian(const std::vector<ContactPairDerivatives>& pairs,
                               const Positions& anchor, const Positions& x, double coefficient,
                               double slip);

}  // namespace shapectl
