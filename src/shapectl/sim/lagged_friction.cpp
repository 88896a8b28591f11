#include <shapectl/sim/lagged_friction.hpp>

#include <sstream>

namespace shapectl {

namespace {

std::string short_number(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

double largest_node_norm(const Eigen::VectorXd& v) {
  double m = 0;
  for (Eigen::Index i = 0; i < v.size() / 3; ++i) m = std::max(m, v.segment<3>(3 * i).norm());
  return m;
}

// Where the object slides: the obstacle with the most normal force on pairs that slip by ε or
// more (their friction at its Coulomb limit; -1 if none), and the largest slip of any pair.
struct Slide {
  int obstacle = -1;
  double slip = 0;
};
Slide find_slide(const ObstacleFriction& f, const Positions& x, std::size_t obstacle_count) {
  std::vector<double> sliding_force(obstacle_count, 0.0);
  Slide s;
  for (std::size_t k = 0; k < f.pairs().size(); ++k) {
    const double y = f.slip(x, k).norm();
    s.slip = std::max(s.slip, y);
    if (y >= f.slip_length()) sliding_force[f.pairs()[k].obstacle] += f.pairs()[k].force;
  }
  for (std::size_t o = 0; o < obstacle_count; ++o)
    if (sliding_force[o] > 0 && (s.obstacle < 0 || sliding_force[o] > sliding_force[s.obstacle]))
      s.obstacle = static_cast<int>(o);
  return s;
}

}  // namespace

StaticsResult solve_with_friction(const StaticsSolver& solver, const EnergyTerms& terms,
                                  const ObstacleContact& contact, const FrictionSettings& settings,
                                  StaticsWorkspace& ws, Positions& x, int max_iterations,
                                  const StaticsWorkspace* chord, const StopRequest& stop) {
  const Positions anchor = x;  // tangential motion counts from the warm start
  EnergyTerms with = terms;
  with.push_back(nullptr);  // the friction term of each solve
  StaticsResult result;

  // 1. Sticking: the pairs at the warm start held with the object's whole load, so the normal
  // forces the lag needs develop without sliding (without pairs there, a frictionless solve).
  {
    std::vector<ContactPair> pairs = contact.pairs(x);
    for (ContactPair& p : pairs) p.force = settings.load;
    const ObstacleFriction sticking(contact, std::move(pairs), anchor, 1.0, settings.slip);
    with.back() = &sticking;
    add_solve(result, solver.solve(with, ws, x, max_iterations, chord, stop));
    if (!result.converged()) return result;
  }

  // 2. Lagged: μ with λ, n, w of the last equilibrium, until the friction forces settle.
  const auto lagged_at = [&](const Positions& at) {
    return ObstacleFriction(contact, contact.pairs(at), anchor, settings.coefficient,
                            settings.slip);
  };
  ObstacleFriction friction = lagged_at(x);
  for (int lag = 1; lag <= settings.max_lags; ++lag) {
    with.back() = &friction;
    add_solve(result, solver.solve(with, ws, x, max_iterations, &ws, stop));
    const Slide slide = find_slide(friction, x, contact.obstacles().size());
    if (slide.obstacle >= 0 && (!result.converged() || slide.slip > settings.size)) {
      result.status = StaticsStatus::NotConverged;
      result.reason = "no equilibrium: the object slides along obstacle '" +
                      contact.obstacles()[slide.obstacle].name + "' (friction " +
                      short_number(settings.coefficient) + " cannot hold it; contacts slid " +
                      short_number(slide.slip) + " m; Newton ended: " + result.reason + ")";
      return result;
    }
    if (!result.converged()) return result;
    // Settled when the friction lagged at this equilibrium pushes as the one it was solved with.
    ObstacleFriction next = lagged_at(x);  // also the next solve's friction
    const double change =
        largest_node_norm(solver.gradient({&next}, x) - solver.gradient({&friction}, x));
    if (change <= solver.effective_tolerance()) {
      result.reason += "; friction settled after " + std::to_string(lag) + " lagged solves";
      return result;
    }
    if (lag == settings.max_lags) {
      result.status = StaticsStatus::NotConverged;
      result.reason = "not converged: the friction forces did not settle after " +
                      std::to_string(lag) + " lagged solves (they still change by " +
                      short_number(change) + " N)";
    }
    friction = std::move(next);
  }
  return result;
}

}  // namespace shapectl
