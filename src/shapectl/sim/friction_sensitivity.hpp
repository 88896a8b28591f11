#pragma once
// Solves with the Jacobian of the lagged friction's fixed point (contact/friction_lag.hpp),
// A = H + L: H the symmetric Hessian (elasticity, grips, barrier, and the friction lagged at the
// equilibrium), factored in a StaticsWorkspace, and L the friction's non-symmetric lag Jacobian.
// A has no Cholesky factor; GMRES on (I + H⁻¹L) x = H⁻¹ b, preconditioned by H's, needs about
// as many solves with it as L has significant directions (L lives on the contact nodes only):
// 6–9 per column for the tests' bar on a table, and never stops short of the tolerance (it
// throws instead).
#include <shapectl/sim/lagged_friction.hpp>

namespace shapectl {

// The friction at a lagged solve's fixed point x: lagged at x itself, slip counted from the
// solve's anchor (its warm start, whatever θ is tried next: the derivatives hold it fixed).
struct FixedPointFriction {
  ObstacleFriction term;  // its Hessian at fixed lag belongs in H
  SparseMatrix lag;       // L, 3n × 3n
};
FixedPointFriction fixed_point_friction(const ObstacleContact& contact,
                                        const FrictionSettings& settings, const Positions& anchor,
                                        const Positions& x);

// A⁻¹ rhs (columns; rows of fixed dofs zero), A = H + lag with H factored in `ws`. For Aᵀ (the
// adjoint) pass lag's transpose.
Eigen::MatrixXd solve_with_lag(const StaticsSolver& solver, const StaticsWorkspace& ws,
                               const SparseMatrix& lag, const Eigen::MatrixXd& rhs);

}  // namespace shapectl
