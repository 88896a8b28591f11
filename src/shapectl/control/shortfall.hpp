#pragma once
// Why a stationary state stays farther from its targets than the user's tolerance: the reasons
// behind a "best effort" status (GUI badge, state messages, `solve` and `run` output).
//
// First, from the targets alone (so the same targets give it whatever pose the optimizer stopped
// at): reach, when a target is farther from where an arm starts than that arm reaches with the
// target's node and the object unstretched (control/reach_bound.hpp). That binds: it is then the
// only reason, and what the end state shows is added to the words as "where it stopped".
// Otherwise the reasons are read from the state itself, in this order (the one that binds
// first), along d = −J_sᵀ r_s, the joint direction in which the targets alone (no barriers)
// would lower the shape error:
//   reach        a gripping arm stretched to its workspace boundary: its tool point at least
//                95 % of the arm's length from its first movable joint (the length: the sum
//                of the fixed distances joint origin → next joint origin → … → tool point);
//   joint limit  a joint within the limit barrier's margin (+ 0.01 rad) of a hard limit while
//                d pushes it further out;
//   collision    a checked sphere pair within the collision margin (+ 1 mm) whose clearance
//                shrinks along d (forward kinematics at θ + 1e-3·d/|d|);
//   buckling     0.02 rad along d the equilibrium is unstable or lost, or snaps: the target
//                nodes move more than 10× (and 1 mm beyond) what the sensitivity predicts.
// None of them: a local minimum of the shape error, said as such.
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/control/optimize.hpp>
#include <shapectl/control/reduced_objective.hpp>

namespace shapectl {

enum class Shortfall { JointLimit, Collision, Reach, Buckling };
// "joint limit", "collision", "reach", "buckling".
const char* to_string(Shortfall shortfall);
bool parse(std::string_view name, Shortfall* shortfall);
std::vector<std::string> shortfall_names(const std::vector<Shortfall>& shortfalls);

struct ShortfallReport {
  std::vector<Shortfall> reasons;  // those that hold, binding first; empty: a local minimum
  std::string detail;              // in words, with names and numbers
};

// The reasons that hold at `at` (a converged equilibrium) for `objective`'s targets. `stop` (a
// time budget) may cut the buckling probe's statics short: buckling is then not reported.
// Non-const: the derivatives factor `at`'s state (ReducedObjective::least_squares).
ShortfallReport find_shortfalls(const ReducedObjective& objective, Evaluation& at,
                                const StopRequest& stop = {});
// The same for the best state of a run that ended with `termination`: a run its iteration or
// time limit cut short, with no reason found, is said to be that, not a local minimum.
ShortfallReport find_run_shortfalls(const ReducedObjective& objective, Evaluation& best,
                                    Termination termination, const StopRequest& stop = {});

}  // namespace shapectl
