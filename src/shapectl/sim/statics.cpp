#include <shapectl/sim/statics.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <tbb/parallel_invoke.h>

#include <shapectl/hand_off.hpp>
#include <shapectl/sim/rigid_motion.hpp>

namespace shapectl {

const char* to_string(StaticsStatus status) {
  switch (status) {
    case StaticsStatus::Converged: return "converged";
    case StaticsStatus::NotConverged: return "not converged";
    case StaticsStatus::Inverted: return "inverted";
    case StaticsStatus::Singular: return "singular";
    case StaticsStatus::Unstable: return "unstable";
  }
  return "?";
}

namespace {
std::vector<char> dof_mask(const std::vector<char>& fixed_node) {
  std::vector<char> dof(3 * fixed_node.size());
  for (std::size_t i = 0; i < fixed_node.size(); ++i)
    for (int k = 0; k < 3; ++k) dof[3 * i + k] = fixed_node[i];
  return dof;
}
std::atomic<long long> total_iterations{0}, total_factorizations{0}, total_analyses{0};

// Eisenstat and Walker's (1996) forcing term η, choice 2 with their safeguard (see
// StaticsOptions::krylov_first_forcing).
class ForcingTerm {
 public:
  ForcingTerm(double first, double tightest) : first_(first), tightest_(tightest) {}
  // η for the iteration that starts at gradient norm `norm`.
  double next(double norm) {
    double eta = previous_norm_ > 0 ? 0.9 * std::pow(norm / previous_norm_, 2) : first_;
    const double safeguard = 0.9 * previous_ * previous_;  // against a lucky drop of |∇E|
    if (safeguard > 0.1) eta = std::max(eta, safeguard);
    previous_ = std::clamp(eta, tightest_, std::max(tightest_, 0.1));
    previous_norm_ = norm;
    return previous_;
  }

 private:
  double first_, tightest_;
  double previous_ = 0, previous_norm_ = 0;
};

std::string sci(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

// The end of the reasons solve() gives: " after 3 iterations".
std::string after_iterations(int iterations) {
  return " after " + std::to_string(iterations) + " iterations";
}
}  // namespace

StaticsTotals statics_totals() {
  return {total_iterations.load(), total_factorizations.load(), total_analyses.load()};
}

StaticsSolver::StaticsSolver(int node_count, std::vector<char> fixed_node, StaticsOptions options)
    : node_count_(node_count), fixed_dof_(dof_mask(fixed_node)), options_(options) {}

StaticsWorkspace StaticsSolver::make_workspace() const {
  return StaticsWorkspace(3 * node_count_, fixed_dof_, options_.backend);
}

namespace {
// An energy that is NaN (an inverted element) counts as infinitely high.
double nan_as_infinity(double e) {
  return std::isnan(e) ? std::numeric_limits<double>::infinity() : e;
}
}  // namespace

void StaticsSolver::zero_fixed_dofs(Eigen::VectorXd& g) const {
  for (int d = 0; d < g.size(); ++d)
    if (fixed_dof_[d]) g[d] = 0;
}

double StaticsSolver::energy(const EnergyTerms& terms, const Positions& x) const {
  double e = 0;
  for (const auto* t : terms) e += t->value(x);
  return nan_as_infinity(e);
}

Eigen::VectorXd StaticsSolver::gradient(const EnergyTerms& terms, const Positions& x) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  for (const auto* t : terms) t->add_gradient(x, g);
  zero_fixed_dofs(g);
  return g;
}

double StaticsSolver::energy_and_gradient(const EnergyTerms& terms, const Positions& x,
                                          Eigen::VectorXd& g) const {
  g = Eigen::VectorXd::Zero(x.size());
  double e = 0;
  for (const auto* t : terms) e += t->value_and_add_gradient(x, g);
  zero_fixed_dofs(g);
  return nan_as_infinity(e);
}

double StaticsSolver::max_force(const Eigen::VectorXd& g) const {
  double m = 0;
  for (int i = 0; i < node_count_; ++i) m = std::max(m, g.segment<3>(3 * i).norm());
  return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
}

namespace {
// Every Hessian the solver uses (Krylov, hessian()) is assembled here; Newton's in factor_at.
const SparseMatrix& assemble_hessian(const EnergyTerms& terms, HessianAssembler& assembler,
                                     const Positions& x, bool projected) {
  return assembler.assemble(terms, x, projected);
}
}  // namespace

bool StaticsSolver::factor_at(const EnergyTerms& terms, StaticsWorkspace& ws, const Positions& x,
                              bool projected, bool assembled) const {
  auto analyze = [&] {
    ws.cholesky.analyze(ws.assembler.matrix(), &ws.assembler.node_pattern());
    ws.analyzed_pattern = ws.assembler.pattern_version();
    ++total_analyses;
  };
  if (!assembled) {
    auto assemble = [&] { ws.assembler.assemble_values(terms, x, projected); };
    // A new pattern: its symbolic analysis, which reads the pattern alone, beside the assembly
    // of the values; the two share the cores.
    if (ws.assembler.learn_pattern(terms, x) != ws.analyzed_pattern) {
      HandOff hand_off;
      tbb::parallel_invoke(hand_off(analyze), hand_off(assemble));
      hand_off.joined();
    } else {
      assemble();
    }
  }
  const SparseMatrix& H = ws.assembler.matrix();
  if (ws.analyzed_pattern != ws.assembler.pattern_version()) analyze();
  const bool ok = ws.cholesky.factorize(H);
  ++total_factorizations;
  ws.has_factor = ok && !projected;
  ws.has_preconditioner = ok;
  if (ok) ws.factor_x = x;
  return ok;
}

bool StaticsSolver::factor(const EnergyTerms& terms, StaticsWorkspace& ws,
                           const Positions& x) const {
  return factor_at(terms, ws, x, false, false);
}

SparseMatrix StaticsSolver::hessian(const EnergyTerms& terms, const Positions& x) const {
  HessianAssembler assembler(3 * node_count_, fixed_dof_);
  return assemble_hessian(terms, assembler, x, false);
}

double StaticsSolver::factor_distance(const StaticsWorkspace& ws, const Positions& x) const {
  if (!ws.has_factor || ws.factor_x.size() != x.size())
    return std::numeric_limits<double>::infinity();
  double d = 0;
  for (int i = 0; i < node_count_; ++i) d = std::max(d, (x - ws.factor_x).segment<3>(3 * i).norm());
  return d;
}

Eigen::MatrixXd StaticsSolver::solve_with_factor(const StaticsWorkspace& ws,
                                                 const Eigen::MatrixXd& rhs) const {
  if (!ws.has_factor)
    throw std::runtime_error("the Hessian at the equilibrium is not positive definite");
  Eigen::MatrixXd masked = rhs;
  for (int d = 0; d < masked.rows(); ++d)
    if (fixed_dof_[d]) masked.row(d).setZero();
  std::lock_guard lock(*ws.solve_mutex);
  return ws.cholesky.solve(masked);
}

std::string StaticsSolver::singular_reason(const StaticsWorkspace& ws) const {
  // Structural checks (every part held) belong to the caller; here the matrix itself, the
  // projected Hessian that just failed to factor, is judged: the spread of its diagonal over
  // free dofs measures how ill-conditioned it is.
  const SparseMatrix& H = ws.assembler.matrix();
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (int d = 0; d < H.rows(); ++d)
    if (!fixed_dof_[d]) {
      const double v = std::abs(H.coeff(d, d));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  const double ratio = hi > 0 && std::isfinite(hi) ? lo / hi : 0;
  return "singular system: the Hessian is numerically singular even after projection (smallest/"
         "largest diagonal stiffness " +
         sci(ratio) +
         (ratio < 1e-12
              ? "; an extreme material, grip stiffness or gravity makes it ill-conditioned)"
              : "; the held nodes may leave a rigid motion free, e.g. a rotation about one node)");
}

double StaticsSolver::max_step(const EnergyTerms& terms, const Positions& x,
                               const Eigen::VectorXd& dx) {
  double alpha = 1;
  for (const auto* t : terms) alpha = std::min(alpha, t->max_step(x, dx));
  return alpha;
}

double StaticsSolver::largest_node_step(const Eigen::VectorXd& dx) const {
  double step = 0;
  for (int i = 0; i < node_count_; ++i) step = std::max(step, dx.segment<3>(3 * i).norm());
  return step;
}

double StaticsSolver::energy_noise(double energy) const {
  return std::max(options_.energy_roundoff, 1e-12 * std::abs(energy)) + 1e-300;
}

Mat3 StaticsSolver::chord_rotation(const StaticsWorkspace& chord, const Positions& x) const {
  return options_.rotate_chord ? best_fit_rotation(chord.factor_x, x) : Mat3::Identity();
}

Eigen::VectorXd StaticsSolver::solve_rotated(const StaticsWorkspace& chord, const Mat3& R,
                                             const Eigen::VectorXd& r, bool rounded) const {
  // H(x) ≈ R H(x_chord) Rᵀ for an object turned by R, so H(x)⁻¹ r ≈ R H(x_chord)⁻¹ Rᵀ r. Fixed
  // nodes have zero residual rows and stay zero (R turns a node's three dofs together).
  const Eigen::VectorXd turned = rotate_nodes(R, r, /*transpose=*/true);
  std::lock_guard lock(*chord.solve_mutex);
  return rotate_nodes(R, rounded ? chord.cholesky.solve_preconditioner(turned)
                                 : chord.cholesky.solve(turned));
}

bool StaticsSolver::chord_step(const EnergyTerms& terms, const StaticsWorkspace& chord,
                               Positions& x, Point& at, NewtonIterate& log) const {
  // The full step with the earlier factorization, kept while it lowers the energy and cuts the
  // force 4-fold.
  const Eigen::VectorXd dx =
      -solve_rotated(chord, chord_rotation(chord, x), at.gradient, options_.single_precision_chord);
  if (!(at.gradient.dot(dx) < 0)) return false;
  // A chord step is all or nothing: one that would pass an obstacle is left to Newton.
  if (max_step(terms, x, dx) < 1) return false;
  Positions trial = x + dx;
  Eigen::VectorXd g_trial;  // in one pass with the energy: a chord step is mostly kept
  const double e_trial = energy_and_gradient(terms, trial, g_trial);
  if (!std::isfinite(e_trial) || e_trial > at.energy + energy_noise(at.energy)) return false;
  const double r_trial = max_force(g_trial);
  if (!(r_trial <= 0.25 * at.residual)) return false;
  log.chord = true;
  log.step_length = 1;
  log.step = largest_node_step(dx);
  x = std::move(trial);
  at = {e_trial, std::move(g_trial), r_trial};
  return true;
}

Eigen::VectorXd StaticsSolver::krylov_direction(const EnergyTerms& terms, StaticsWorkspace& ws,
                                                const StaticsWorkspace& chord, const Positions& x,
                                                const Eigen::VectorXd& g, double target, bool exact,
                                                bool projected, NewtonIterate& log) const {
  // Preconditioned conjugate gradients on H dx = −g. The chord's factor is of the Hessian at a
  // nearby state: H is close to it, so few products reach the tolerance. Assembling H costs a
  // fraction of factoring it on large meshes. Fixed dofs: H has identity rows there and g zeros,
  // so dx stays zero on them.
  const SparseMatrix& H = assemble_hessian(terms, ws.assembler, x, projected);
  const Mat3 R = chord_rotation(chord, x);
  // An exact step's factor is a cold solve's own, used a few times: its rounded copy would
  // cost more than it saves (3-4 ms at 12k tets, where a solve in double costs ~1 ms).
  const bool rounded = options_.single_precision_chord && !exact;
  auto precondition = [&](const Eigen::VectorXd& r) { return solve_rotated(chord, R, r, rounded); };
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(g.size());
  Eigen::VectorXd r = -g;
  double previous = r.norm();
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  for (int k = 1; k <= options_.krylov_iterations; ++k) {
    const Eigen::VectorXd Hp = H.selfadjointView<Eigen::Lower>() * p;
    const double curvature = p.dot(Hp);
    // Not positive definite along p: Newton factors. pᵀHp ≤ 0 (not NaN) proves H indefinite.
    if (!(curvature > 0)) {
      log.negative_curvature = curvature <= 0;
      return {};
    }
    const double alpha = rz / curvature;
    dx += alpha * p;
    r -= alpha * Hp;
    const double norm = r.norm();
    if (norm <= target) {
      log.krylov = k;
      return g.dot(dx) < 0 ? dx : Eigen::VectorXd();
    }
    // An exact step gives up as soon as the last product's rate cannot reach the target within
    // the products left: a factorization is then cheaper than trying on (the soft cantilever
    // from rest, whose large steps change the Hessian much).
    const double rate = norm / previous;
    if (exact &&
        !(rate < 1 && std::log(target / norm) / std::log(rate) <= options_.krylov_iterations - k))
      return {};
    previous = norm;
    z = precondition(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return {};
}

bool StaticsSolver::krylov_step(const EnergyTerms& terms, StaticsWorkspace& ws,
                                const StaticsWorkspace& chord, double target, bool exact,
                                Positions& x, Point& at, NewtonIterate& log) const {
  Eigen::VectorXd dx =
      krylov_direction(terms, ws, chord, x, at.gradient, target, exact, false, log);
  // Indefinite: the projected Hessian is positive definite, and its factor would be the
  // preconditioner's match as well. (log.negative_curvature stays: Newton then factors only it.)
  // Not for an exact step: its factor, of a state before a large step, is no match.
  if (dx.size() == 0 && log.negative_curvature && !exact) {
    dx = krylov_direction(terms, ws, chord, x, at.gradient, target, exact, true, log);
    log.projected = dx.size() > 0;
  }
  if (dx.size() > 0 && line_search(terms, dx, x, at, log, false)) return true;
  log.krylov = 0;
  log.projected = false;
  return false;
}

Eigen::VectorXd StaticsSolver::newton_direction(const EnergyTerms& terms, StaticsWorkspace& ws,
                                                const Positions& x, const Eigen::VectorXd& g,
                                                NewtonIterate& log, int& factorizations,
                                                bool assembled, const StopRequest& stop) const {
  // The true Hessian at x, if it gives a descent direction; else the PSD-projected one. A
  // true Hessian known to be indefinite is not tried: its factorization would fail, after
  // 35-60 % of the columns on the 50k bar.
  if (!log.negative_curvature) {
    ++factorizations;
    if (factor_at(terms, ws, x, false, assembled)) {
      Eigen::VectorXd dx = -ws.cholesky.solve(g);
      if (g.dot(dx) < 0) return dx;
    }
  }
  if (stop && stop()) return {};  // the caller reports the stop
  log.projected = true;
  ++factorizations;
  if (!factor_at(terms, ws, x, true, false)) return {};
  return -ws.cholesky.solve(g);
}

bool StaticsSolver::line_search(const EnergyTerms& terms, const Eigen::VectorXd& dx, Positions& x,
                                Point& at, NewtonIterate& log, bool relaxed) const {
  // Backtracking (see the header). Inverted trial states have E = +inf. Relaxed (the
  // watchdog's step): the first finite state is taken.
  const double slope = at.gradient.dot(dx);
  const double noise = energy_noise(at.energy);
  // From the longest step on which no surface passes through an obstacle (contact's CCD): the
  // energy of the end state alone cannot see a surface that went through and out the far side.
  double alpha = std::min(1.0, max_step(terms, x, dx));
  for (int k = 0; k < 40; ++k, alpha *= 0.5) {
    Positions trial = x + alpha * dx;
    const double e_trial = energy(terms, trial);
    if (!std::isfinite(e_trial)) continue;
    // Clearly higher: rejected before its gradient is computed.
    if (!relaxed && e_trial > at.energy + noise && e_trial > at.energy + 1e-4 * alpha * slope)
      continue;
    Eigen::VectorXd g_trial = gradient(terms, trial);
    const double r_trial = max_force(g_trial);
    if (!std::isfinite(r_trial)) continue;
    if (!relaxed && !decreases(at, alpha * slope, alpha, e_trial, g_trial)) continue;
    log.step_length = alpha;
    log.step = largest_node_step(alpha * dx);
    x = std::move(trial);
    at = {e_trial, std::move(g_trial), r_trial};
    return true;
  }
  return false;
}

bool StaticsSolver::decreases(const Point& from, double slope, double alpha, double energy,
                              const Eigen::VectorXd& gradient) const {
  if (energy <= from.energy + 1e-4 * slope) return true;  // Armijo
  // Energy within round-off of the start: the force norm decides.
  return energy <= from.energy + energy_noise(from.energy) &&
         gradient.squaredNorm() <= (1 - 1e-4 * alpha) * from.gradient.squaredNorm();
}

// The state solve()'s phases share. Named flags for what the loop may try next.
struct StaticsSolver::Run {
  // The watchdog's reference (see the header): the state before its relaxed step.
  struct Watch {
    Positions x;
    Point at;
    double slope = 0;  // ∇E·dx of the relaxed step
    int iteration = 0;
  };

  Run(Positions& x, int max_iterations, const StopRequest& stop, const StaticsOptions& options)
      : x(x),
        max_iterations(max_iterations),
        stop(stop),
        forcing(options.krylov_first_forcing, options.krylov_tolerance) {}
  bool stop_requested() const { return stop && stop(); }
  // A solve that ends unconverged during the watch returns the state before the relaxed step.
  void restore() {
    x = std::move(watch->x);
    at = std::move(watch->at);
    watch.reset();
    result.residual = at.residual;
    result.energy = at.energy;
  }
  // The watchdog gives up at iteration `it`: back to its reference, logged as a step.
  void go_back(int it) {
    restore();
    result.log.push_back(
        {.iteration = it, .residual = at.residual, .energy = at.energy, .went_back = true});
  }
  void end(StaticsStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
  }
  // Ended by a stop request at iteration `it` (from the state before the watched step, if any).
  void stopped(int it) {
    if (watch) restore();
    end(StaticsStatus::NotConverged,
        "stopped (time limit): residual " + sci(at.residual) + " N" + after_iterations(it));
  }

  Positions& x;
  Point at;  // energy, gradient and residual at x
  StaticsResult result;
  double tolerance = 0;  // effective_tolerance()
  int max_iterations;
  const StopRequest& stop;
  // The nearby factorization chord and Krylov steps use while they take full steps; null once
  // the solve factors anew (or when it was given none).
  const StaticsWorkspace* nearby = nullptr;
  bool warm = false;  // given a nearby factorization; else cold: Krylov steps if cold_krylov_steps
  bool own_factor_fits = false;  // ws holds a factorization this solve made that Krylov may use
  // ws's assembler holds the true Hessian at x (a failed exact Krylov step's): Newton factors it.
  bool true_hessian_assembled = false;
  ForcingTerm forcing;
  bool may_relax = false;  // the next Newton step is the watchdog's relaxed one
  std::optional<Watch> watch;
};

bool StaticsSolver::start(const EnergyTerms& terms, Run& run, const StaticsWorkspace* chord) const {
  Point& at = run.at;
  at.energy = energy_and_gradient(terms, run.x, at.gradient);
  if (!std::isfinite(at.energy)) {
    run.end(StaticsStatus::Inverted,
            "the starting state has an inverted element or a non-finite energy");
    return false;
  }
  at.residual = max_force(at.gradient);
  run.tolerance = effective_tolerance();
  if (!(run.tolerance < std::numeric_limits<double>::infinity())) {
    run.result.residual = at.residual;
    run.result.energy = at.energy;
    run.end(StaticsStatus::NotConverged,
            "not converged: the force tolerance " + sci(run.tolerance) + " N is non-finite");
    return false;
  }
  // Chord steps first: the true Hessian's factor of a nearby state is used while it works.
  // This saves the factorization, the dominant cost, on warm re-solves. Once the solve factors
  // anew it stays with Newton steps (solved by Krylov with its own factor first): chord steps
  // from a factor of an earlier iterate stalled Newton near buckling (seconds instead of
  // milliseconds in `shapectl bench`).
  if (chord && chord->has_factor && chord->factor_x.size() == run.x.size()) run.nearby = chord;
  run.warm = run.nearby != nullptr;
  // The watchdog (see the header): a cold solve's first Newton step is taken in full while no
  // element inverts, even where it raises the energy; the solve returns to the state before it
  // (and to the descent rule, for good) unless the energy falls below that state's Armijo level
  // within watchdog_iterations iterations.
  run.may_relax = !chord && options_.watchdog_iterations > 0;
  return true;
}

void StaticsSolver::watchdog_verdict(Run& run, int it) const {
  if (!run.watch) return;
  const Point& at = run.at;
  if (decreases(run.watch->at, run.watch->slope, 1, at.energy, at.gradient)) run.watch.reset();
  else if (it - run.watch->iteration >= options_.watchdog_iterations ||
           at.residual <= run.tolerance || !std::isfinite(at.residual))
    run.go_back(it);  // not below the start in time, or an equilibrium above it
}

bool StaticsSolver::convergence_test(Run& run, int it) const {
  watchdog_verdict(run, it);
  const Point& at = run.at;
  run.result.iterations = it;
  run.result.residual = at.residual;
  run.result.energy = at.energy;
  if (!std::isfinite(at.residual)) {
    run.end(StaticsStatus::NotConverged, "not converged: non-finite force" + after_iterations(it));
  } else if (at.residual <= run.tolerance && run.x.allFinite()) {
    run.end(StaticsStatus::Converged, "residual " + sci(at.residual) + " N" + after_iterations(it));
  } else if (it == run.max_iterations) {
    if (run.watch) run.restore();  // `at` is then the state before the watched step
    run.end(StaticsStatus::NotConverged,
            "not converged: residual " + sci(at.residual) + " N" + after_iterations(it));
  } else if (run.stop_requested()) {
    run.stopped(it);
  } else {
    return false;
  }
  return true;
}

bool StaticsSolver::reuse_step(const EnergyTerms& terms, StaticsWorkspace& ws, Run& run,
                               NewtonIterate& log) const {
  // A Krylov step's residual: η |∇E|, but no less than a quarter of the tolerance. Every
  // nodal force is at most |∇E|, so below that the step's linear model is already converged,
  // and solving further is wasted. A cold solve's Krylov steps stand in for its Newton steps:
  // they solve as far as the tolerance, so the iterates are Newton's (cold_krylov_steps).
  const double gradient_norm = run.at.gradient.norm();
  const double exact_target = 0.25 * run.tolerance;
  const double krylov_target =
      std::max(run.forcing.next(gradient_norm) * gradient_norm, exact_target);
  if (run.nearby && options_.chord_steps && chord_step(terms, *run.nearby, run.x, run.at, log))
    return true;
  // Then a Newton step solved by conjugate gradients with the chord's factor: kept while it
  // takes full steps (a shorter one means the factor no longer fits: Newton factors anew).
  // After a factorization of its own, the solve's next Newton steps are first solved so,
  // preconditioned with it (the same rule). A warm solve's only with a factor that is cheap
  // to solve with (SparseCholesky::cheap_to_solve); a cold solve's exact steps with any: each
  // that succeeds saves a whole factorization.
  const StaticsWorkspace* preconditioner = run.nearby            ? run.nearby
                                           : run.own_factor_fits ? &ws
                                                                 : nullptr;
  const bool try_krylov =
      preconditioner &&
      (run.warm ? options_.krylov_steps && preconditioner->cholesky.cheap_to_solve()
                : options_.cold_krylov_steps);
  if (try_krylov && krylov_step(terms, ws, *preconditioner, run.warm ? krylov_target : exact_target,
                                !run.warm, run.x, run.at, log)) {
    if (log.step_length != 1) run.nearby = nullptr;
    run.own_factor_fits = run.own_factor_fits && log.step_length == 1;
    return true;
  }
  run.true_hessian_assembled = try_krylov && !run.warm && !log.negative_curvature;
  return false;
}

StaticsSolver::Outcome StaticsSolver::newton_step(const EnergyTerms& terms, StaticsWorkspace& ws,
                                                  Run& run, NewtonIterate& log) const {
  run.nearby = nullptr;
  run.own_factor_fits = false;
  // The stability check: the true Hessian if it factors, else the projected one.
  const Eigen::VectorXd dx =
      newton_direction(terms, ws, run.x, run.at.gradient, log, run.result.factorizations,
                       run.true_hessian_assembled, run.stop);
  const int it = log.iteration;
  if (dx.size() == 0) {
    if (run.stop_requested()) {
      run.stopped(it);
      return Outcome::Ended;
    }
    if (run.watch) {
      run.go_back(it);
      return Outcome::WentBack;
    }
    run.end(StaticsStatus::Singular, singular_reason(ws));
    return Outcome::Ended;
  }
  return line_search_step(terms, ws, run, dx, log);
}

StaticsSolver::Outcome StaticsSolver::line_search_step(const EnergyTerms& terms,
                                                       const StaticsWorkspace& ws, Run& run,
                                                       const Eigen::VectorXd& dx,
                                                       NewtonIterate& log) const {
  const int it = log.iteration;
  const double residual_before = run.at.residual;
  const bool relax = run.may_relax;
  run.may_relax = false;
  if (relax) run.watch = Run::Watch{run.x, run.at, run.at.gradient.dot(dx), it};
  if (!line_search(terms, dx, run.x, run.at, log, relax)) {
    if (run.watch) {
      run.go_back(it);
      return Outcome::WentBack;
    }
    run.end(StaticsStatus::NotConverged,
            "line search failed at residual " + sci(residual_before) + " N" + after_iterations(it));
    return Outcome::Ended;
  }
  log.relaxed = relax;
  // In a cold solve, exact Krylov steps follow a full Newton step with the true Hessian only:
  // after a shorter or a projected one the Hessian has changed too much for its factor.
  run.own_factor_fits =
      ws.has_preconditioner && (run.warm || (log.step_length == 1 && !log.projected));
  return Outcome::Stepped;
}

void add_solve(StaticsResult& sum, StaticsResult next) {
  next.iterations += sum.iterations;
  next.factorizations += sum.factorizations;
  next.log.insert(next.log.begin(), sum.log.begin(), sum.log.end());
  sum = std::move(next);
}

StaticsResult StaticsSolver::solve(const EnergyTerms& terms, StaticsWorkspace& ws, Positions& x,
                                   int max_iterations, const StaticsWorkspace* chord,
                                   const StopRequest& stop) const {
  Run run(x, max_iterations > 0 ? max_iterations : options_.max_iterations, stop, options_);
  if (!start(terms, run, chord)) return std::move(run.result);
  for (int it = 0;; ++it) {
    if (convergence_test(run, it)) return std::move(run.result);
    NewtonIterate log{.iteration = it, .residual = run.at.residual, .energy = run.at.energy};
    ++total_iterations;
    const Outcome outcome =
        reuse_step(terms, ws, run, log) ? Outcome::Stepped : newton_step(terms, ws, run, log);
    if (outcome == Outcome::Ended) return std::move(run.result);
    if (outcome == Outcome::Stepped) run.result.log.push_back(log);
  }
}

}  // namespace shapectl
