#include <shapectl/sim/contact_stiffness.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <shapectl/contact/barrier.hpp>

namespace shapectl {

namespace {
std::string raise_description(double scale, double gap) {
  char text[96];
  std::snprintf(text, sizeof text, "contact stiffness ×%.3g (a gap of %.2g m < d̂/100)", scale, gap);
  return text;
}
}  // namespace

double stiffness_raise(double d_min, double dhat) {
  return barrier(d_min, dhat).first / barrier(target_gap * dhat, dhat).first;
}

double ContactTerms::smallest_gap(const Positions& x) const {
  double d = std::numeric_limits<double>::infinity();
  if (obstacles) d = std::min(d, obstacles->summary(x).min_distance);
  if (self) d = std::min(d, self->min_distance(x));
  return d;
}

StaticsResult solve_adapting_stiffness(const SolveAtScale& solve, const ContactTerms& contact,
                                       double dhat, double scale, StaticsWorkspace& ws,
                                       Positions& x, const StaticsWorkspace* chord,
                                       bool from_warm_start, const StopRequest& stop) {
  const Positions warm_start = from_warm_start ? x : Positions();
  StaticsResult result = solve(scale, x, chord);
  result.contact_scale = scale;
  for (int raise = 0; raise < max_stiffness_raises; ++raise) {
    // A refused start (Inverted) left x where it was; a stopped solve is not continued.
    const bool ended_at_an_iterate =
        result.converged() || result.status == StaticsStatus::NotConverged;
    if (!ended_at_an_iterate || (stop && stop())) break;
    const double gap = contact.smallest_gap(x);
    if (!(gap > 0 && gap < pressed_gap * dhat)) break;
    const double raised = result.contact_scale * stiffness_raise(gap, dhat);
    const std::string why = raise_description(raised, gap);
    Positions y = from_warm_start ? warm_start : x;
    ws.forget_factor();  // of the Hessian at the lower κ: neither a chord nor a sensitivity's
    StaticsResult next = solve(raised, y, nullptr);
    if (!next.converged() && result.converged()) {  // keep the equilibrium at the lower κ
      ws.forget_factor();
      result.iterations += next.iterations;
      result.factorizations += next.factorizations;
      result.log.insert(result.log.end(), next.log.begin(), next.log.end());
      result.reason += "; " + why + " dropped: " + next.reason;
      break;
    }
    next.reason += "; " + why;
    add_solve(result, std::move(next));
    result.contact_scale = raised;
    x = std::move(y);
  }
  return result;
}

}  // namespace shapectl
