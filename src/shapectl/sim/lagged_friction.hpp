#pragma once
// Statics with Coulomb friction on the obstacles (contact/friction.hpp), by IPC's lagged
// iterations: the friction's normal forces, normals and closest-point weights are frozen at a
// lag state, the equilibrium is solved with them, and the lag moves to that equilibrium until
// the friction forces settle.
//
// The anchor (the state tangential motion counts from) is the warm start x₀: the previous
// equilibrium for a robot moving along a path (one quasi-static step), the rest shape for
// `shapectl statics`. The lag points:
//   1. sticking: the pairs at x₀, each held by a tangential resistance of the object's whole
//      load (μλ := load), so the normal forces develop without sliding;
//   2. then μ with λ, n, w of the previous solve's equilibrium, until the friction forces they
//      give at the new equilibrium differ from those it was solved with by at most the force
//      tolerance (then it balances the unlagged forces too), or `max_lags` solves.
// A friction that cannot hold the object (the tangential load beyond μ × the normal force)
// leaves no equilibrium: the lagged solve fails and the result says which obstacle the object
// slides along. No stick–slip history is kept beyond the anchor; no dynamics.
// The result is a fixed point: x balances the friction lagged at x itself. Its sensitivities
// (friction_sensitivity.hpp) differentiate that balance with the anchor held fixed.
#include <shapectl/contact/friction.hpp>
#include <shapectl/sim/statics.hpp>

namespace shapectl {

struct FrictionSettings {
  double coefficient = 0;  // μ
  double slip = 0;         // ε, m
  double load = 0;         // the object's load, N (the sticking solve's resistance)
  double size = 0;         // the object's bounding-box diagonal, m (a slide beyond it runs away)
  // Lagged solves after the sticking one. Each is a short Newton continuation; the lag settles
  // linearly, slower the stiffer the barrier (a raised κ: contact_stiffness.hpp).
  int max_lags = 25;
};

// Equilibrium of `terms` plus friction on `contact`'s pairs from the warm start x (the anchor);
// max_iterations, chord and stop as for StaticsSolver::solve (chord for the first solve only;
// each later one starts from the previous factorization). Iterations and factorizations are
// the totals of every solve.
StaticsResult solve_with_friction(const StaticsSolver& solver, const EnergyTerms& terms,
                                  const ObstacleContact& contact, const FrictionSettings& settings,
                                  StaticsWorkspace& ws, Positions& x, int max_iterations,
                                  const StaticsWorkspace* chord, const StopRequest& stop);

}  // namespace shapectl
