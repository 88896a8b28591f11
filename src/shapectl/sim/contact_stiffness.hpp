#pragma once
// Adaptive barrier stiffness, as IPC adapts κ (Li et al. 2020, Sec. 4.3 and its supplement):
// where the loads press the object much harder onto an obstacle (or onto itself) than its
// weight, for which the default κ is made, an equilibrium found with that κ has gaps far below
// d̂ (micrometres for d̂ = 1 mm), where the barrier's curvature grows as d̂²/d² and Newton's
// system is badly conditioned (Newton often stalls there). So after a solve that ends with its
// smallest gap d_min below pressed_gap × d̂, κ is raised by the factor that would hold the
// tightest pair's force at target_gap × d̂,
//     κ ← κ · b′(d_min) / b′(target_gap · d̂),
// and Newton continues from where it ended (at most max_stiffness_raises times). IPC doubles κ
// per time step while gaps keep shrinking; a statics solve has one step, so the factor is
// computed at once: near contact b′(d) ≈ −d̂²/d, the gap grows about in proportion to κ at a
// given force, and one raise usually suffices. The equilibrium reported is at the final κ, and
// every derivative at it (Hessian, ∂F/∂θ, dx̂/dθ) is at that κ too: the state carries the scale.
#include <functional>
#include <optional>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/contact/self_contact.hpp>
#include <shapectl/sim/statics.hpp>

namespace shapectl {

// Below a hundredth of d̂ a gap counts as pressed: the barrier's curvature is then ~2300 times
// its value at d̂/2 (the default κ's design gap). Above it nothing changes, so an object resting
// on obstacles under its own weight (gaps near d̂/2) never pays for the check beyond one pass.
inline constexpr double pressed_gap = 0.01;  // × d̂
// Where a raise puts the tightest pair: ten times the threshold, so a load must grow about
// tenfold before the next raise, and κ grows no more than the worst pair needs.
inline constexpr double target_gap = 0.1;  // × d̂
inline constexpr int max_stiffness_raises = 3;

// The factor on κ for a smallest gap d_min in (0, pressed_gap·d̂): b′(d_min) / b′(target_gap·d̂).
double stiffness_raise(double d_min, double dhat);

// The contact terms of one state, κ multiplied by its scale (and the obstacles posed at its
// joints); none where the scene has none.
struct ContactTerms {
  std::optional<ObstacleContact> obstacles;
  std::optional<SelfContact> self;

  // The smallest gap over both at x; +inf if no pair is within d̂.
  double smallest_gap(const Positions& x) const;
};

// A solve from x at contact stiffness scale `scale` (κ × scale), from `chord`'s factorization
// if given (ObjectStatics::solve, with or without friction).
using SolveAtScale =
    std::function<StaticsResult(double scale, Positions& x, const StaticsWorkspace* chord)>;
// solve(scale, x, chord), then while it ended at an iterate (converged, or not converged: Newton
// stalls at such gaps) with a gap below pressed_gap·d̂: κ raised (stiffness_raise) and solved
// again from there (from the warm start if `from_warm_start`: lagged friction anchors there),
// without a chord (the earlier factor is of the Hessian at the lower κ). A raise that does not
// converge after one that did is dropped: x and the result stay at the κ that converged, the
// raise's work counted and its failure in the reason. No raise once `stop` asks. The result's
// contact_scale is the scale of x; ws holds no factorization at another scale.
StaticsResult solve_adapting_stiffness(const SolveAtScale& solve, const ContactTerms& contact,
                                       double dhat, double scale, StaticsWorkspace& ws,
                                       Positions& x, const StaticsWorkspace* chord,
                                       bool from_warm_start, const StopRequest& stop);

}  // namespace shapectl
