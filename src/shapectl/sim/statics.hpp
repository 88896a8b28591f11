#pragma once
// Quasi-static equilibrium x̂ = argmin_x E(x) (paper eq. 1) by Newton's method with a
// backtracking line search. Newton factors the true Hessian; only a step where that fails
// (indefinite far from equilibrium) falls back to element-wise PSD-projected Hessians.
//
// Convergence criterion: every free node's force (the energy gradient) is at most
// max(force_tolerance, force_roundoff), and the residual, the energy and every position are
// finite. force_roundoff is the force that round-off alone leaves at the exact equilibrium
// (tens of ulps of the largest elastic force contributions, see roundoff_scale): a
// tolerance below it could never be met, and an answer within it is as exact as doubles allow.
// Line search: Armijo on the energy while the energy change a step predicts is above the
// energy's round-off (energy_roundoff); below that, energy differences are noise, and a step is
// accepted when the energy does not rise beyond round-off and the force norm falls (Armijo on
// |∇E|², which Newton's step with the true Hessian descends: d/dα |∇E|² = −2|∇E|²).
// "Not converged" thus means a force above that tolerance, never a tolerance out of reach.
// Watchdog (Chamberlain et al. 1982): a cold solve's first Newton step (no nearby factor) is
// taken in full wherever no element inverts, even where it raises the energy. From rest, that
// step is the linear solution: on soft, large-deflection objects (a plate or cantilever sagging
// under gravity) it stretches them, and the energy test cut it to a small fraction, after which
// Newton crept along the bending arc (the 21,600-tet plate: 24 iterations). Newton from the
// full step's state rotates into place in a few (7). The solve goes back to the state before
// that step, and on with the energy test only, unless within watchdog_iterations iterations
// the energy falls below that state's Armijo level; an equilibrium found above it, and any
// failure or end of the solve during the watch, also go back. The convergence test is the
// same; on every case measured (docs/benchmarks.md) so is the equilibrium, to < 1e-6 m.
#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/linalg/sparse_cholesky.hpp>
#include <shapectl/sim/hessian_assembler.hpp>

namespace shapectl {

// Unstable: an equilibrium where the Hessian is not positive definite (a saddle, e.g. the
// bar at the tipping point of a buckle); reported by the optimizers' stability check.
enum class StaticsStatus { Converged, NotConverged, Inverted, Singular, Unstable };
const char* to_string(StaticsStatus status);

struct StaticsOptions {
  double force_tolerance = 1e-6;  // N: converged when every free node's force is below this
  // N: the force round-off leaves at the equilibrium; the effective tolerance is never lower.
  double force_roundoff = 0;
  // J: energy differences below this are round-off (at least 1e-12 |E|).
  double energy_roundoff = 0;
  int max_iterations = 100;
  // Which sparse Cholesky; by default chosen by system size (SparseCholesky::choose).
  std::optional<SparseCholesky::Backend> backend;
  // In a warm solve (one given a nearby factorization, the chord): when a chord step fails, a
  // Newton step whose system is solved by conjugate gradients
  // preconditioned with the chord's (stale) factorization, before factoring anew: an inexact
  // Newton step (at most krylov_iterations products). The same after the solve's own
  // factorizations, preconditioned with the last one. Where the true Hessian shows negative
  // curvature, the projected one is solved so (a projected Newton step without factoring).
  bool krylov_steps = true;
  // In a cold solve (no nearby factorization), Krylov steps after its own factorizations too:
  // exact ones, solved as far as the tolerance (in double precision), so the iterates are
  // Newton's, one factorization fewer each, and given up as soon as the conjugate gradients'
  // rate shows the tolerance out of reach in krylov_iterations products. From rest on the 12k
  // bar: 2 iterations and 1 factorization, 27-29 ms against 40 ms with two factorizations; an
  // inexact step (the forcing term) took an iteration more (docs/benchmarks.md, session 6).
  bool cold_krylov_steps = true;
  bool chord_steps = true;  // off: a nearby factorization is used by Krylov steps only (tests)
  // How closely a Krylov step solves Newton's system, as a relative residual η (Eisenstat and
  // Walker 1996, choice 2): krylov_first_forcing for a solve's first iteration, then
  // 0.9 (|∇E_k| / |∇E_k−1|)², within [krylov_tolerance, 0.1]. Far from the equilibrium a rough
  // Newton step does as well as an exact one; near it η tightens as convergence turns quadratic.
  double krylov_first_forcing = 1e-2;
  double krylov_tolerance = 1e-4;
  // A CG product costs a solve with the factor (and a product with H): on the 12k-tet bar ~1/15
  // of a factorization, so a Krylov step that needs more than this is better refactored.
  int krylov_iterations = 12;
  // Chord and Krylov steps turn the nearby factorization with the object's best-fit rotation
  // since it was made (see rigid_motion.hpp); off only to measure what that saves.
  bool rotate_chord = true;
  // The watchdog (see the top of this file): iterations a cold solve's first, relaxed Newton
  // step gets to bring the energy below where it started; 0: off.
  int watchdog_iterations = 6;
  // Chord and Krylov steps solve with the nearby factorization rounded to single precision
  // (SparseCholesky::solve_preconditioner): half the memory traffic of the solve that
  // dominates them. Their steps are checked by the true residual, so the equilibrium and the
  // sensitivities (which solve in double) are unchanged; off only to measure what it saves.
  bool single_precision_chord = true;
};

struct NewtonIterate {
  int iteration = 0;
  double residual = 0;     // largest nodal force norm at the start of the iteration, N
  double energy = 0;       // J
  double step = 0;         // largest nodal displacement of the accepted step, m
  double step_length = 0;  // line-search factor α
  bool projected = false;  // the PSD-projected Hessian was used
  bool chord = false;      // an earlier factorization was reused (no new one)
  int krylov = 0;          // conjugate-gradient products of a Krylov step (0: none)
  // A Krylov step met a direction p with pᵀHp ≤ 0: H is not positive definite, so only the
  // projected Hessian was factored (the true one would certainly have failed).
  bool negative_curvature = false;
  bool relaxed = false;    // the watchdog's step, accepted without lowering the energy
  bool went_back = false;  // the watchdog gave up: back at the state before its step (no step)
};

struct StaticsResult {
  StaticsStatus status = StaticsStatus::NotConverged;
  std::string reason;  // why it stopped, e.g. "residual 3e-2 N after 50 iterations"
  int iterations = 0;
  int factorizations = 0;  // numeric factorizations this solve did
  double residual = 0;     // largest nodal force norm at the returned state, N
  double energy = 0;
  std::vector<NewtonIterate> log;
  // The factor on the contact stiffness κ the returned state is at (ObjectStatics' adaptive
  // barrier, sim/contact_stiffness.hpp); 1 unless contact pressed a gap below d̂/100.
  double contact_scale = 1;
  bool converged() const { return status == StaticsStatus::Converged; }
};

// A solve made of several Newton runs: `next` after `sum`, with next's status, reason and
// state, the iterations, factorizations and log of both.
void add_solve(StaticsResult& sum, StaticsResult next);

// The mutable half of statics: the assembled Hessian, its factorization and the point it
// belongs to (plus the symbolic analysis and buffers, reused from call to call). Made by
// StaticsSolver::make_workspace. One thread at a time changes it; solving with its factor
// (solve_with_factor, or as another solve's chord source) is safe from several threads.
struct StaticsWorkspace {
  StaticsWorkspace(int dof_count, std::vector<char> fixed_dof,
                   std::optional<SparseCholesky::Backend> backend)
      : assembler(dof_count, std::move(fixed_dof)), cholesky(backend) {}
  // Drops the factorization (the buffers and the symbolic analysis stay).
  void forget_factor() { has_factor = has_preconditioner = false; }

  HessianAssembler assembler;
  SparseCholesky cholesky;
  int analyzed_pattern = 0;  // the assembler's pattern_version() the Cholesky analysed (0: none)
  // The factor is of the true Hessian at `factor_x` (sensitivities and chord steps may use it).
  bool has_factor = false;
  // The factor is of the true or of the projected Hessian at `factor_x` (Krylov steps of the
  // same solve may precondition with it).
  bool has_preconditioner = false;
  Positions factor_x;
  // CHOLMOD's solve writes to its common workspace: solves with this factor take turns.
  std::unique_ptr<std::mutex> solve_mutex = std::make_unique<std::mutex>();
};

using EnergyTerms = std::vector<const EnergyTerm*>;

// Asked before every Newton iteration; true stops the solve there (NotConverged, "stopped"):
// a time budget (--max-seconds) reaches into long solves.
using StopRequest = std::function<bool()>;

// Totals over the whole process since it started, for benchmarks (`shapectl bench --sizes`):
// Newton and chord iterations, numeric factorizations (stability checks included), and
// symbolic analyses (one per workspace and pattern: WorkspacePool shares them across solves).
struct StaticsTotals {
  long long iterations = 0;
  long long factorizations = 0;
  long long analyses = 0;
};
StaticsTotals statics_totals();

// The fixed description of a statics problem (size, fixed dofs, options) and the algorithms on
// it. Const and shareable across threads; everything that changes lives in the caller's
// StaticsWorkspace and positions. The energy terms are passed per call (they may depend on the
// robot's configuration); they must describe the same problem each time (same Hessian
// elements).
class StaticsSolver {
 public:
  // fixed_node[i]: node i keeps the position it has in x (Dirichlet). Sizes: n nodes, 3n unknowns.
  StaticsSolver(int node_count, std::vector<char> fixed_node, StaticsOptions options = {});
  StaticsWorkspace make_workspace() const;

  // Newton from x (warm start), overwritten with the equilibrium or the last iterate; the
  // workspace is left with the factorization of the last Newton step (or none). When `chord`
  // holds a true-Hessian factorization (of a nearby state; it may be `ws` itself), Newton tries
  // steps with it first. max_iterations > 0 overrides the options' limit for this call.
  StaticsResult solve(const EnergyTerms& terms, StaticsWorkspace& ws, Positions& x,
                      int max_iterations = 0, const StaticsWorkspace* chord = nullptr,
                      const StopRequest& stop = {}) const;

  // Total energy and its gradient (fixed dofs zeroed) at x.
  double energy(const EnergyTerms& terms, const Positions& x) const;
  Eigen::VectorXd gradient(const EnergyTerms& terms, const Positions& x) const;
  // Both in one pass over the elements (EnergyTerm::value_and_add_gradient; the same bits).
  double energy_and_gradient(const EnergyTerms& terms, const Positions& x,
                             Eigen::VectorXd& gradient) const;
  // The longest step α ∈ (0, 1] along dx from x that every term admits the whole way
  // (EnergyTerm::max_step: contact's continuous collision detection). Every step the solver
  // takes is bounded by it, so x never passes through an obstacle.
  static double max_step(const EnergyTerms& terms, const Positions& x, const Eigen::VectorXd& dx);
  // Factors the true Hessian at x into `ws`; false if it is not positive definite (then `ws`
  // holds no factorization).
  bool factor(const EnergyTerms& terms, StaticsWorkspace& ws, const Positions& x) const;
  // Y = H⁻¹ rhs with the factorization `ws` holds (rows of fixed dofs zero). Throws
  // std::runtime_error when it holds none.
  Eigen::MatrixXd solve_with_factor(const StaticsWorkspace& ws, const Eigen::MatrixXd& rhs) const;
  // Largest distance of a node of x from the point of `ws`'s factorization; +inf without one.
  double factor_distance(const StaticsWorkspace& ws, const Positions& x) const;
  // The true Hessian at x, lower triangle, fixed dofs eliminated (for tests and tools).
  SparseMatrix hessian(const EnergyTerms& terms, const Positions& x) const;

  int node_count() const { return node_count_; }
  const std::vector<char>& fixed_dof() const { return fixed_dof_; }
  const StaticsOptions& options() const { return options_; }
  // The tolerance Newton stops at: the larger of force_tolerance and force_roundoff.
  double effective_tolerance() const {
    return std::max(options_.force_tolerance, options_.force_roundoff);
  }

 private:
  // Energy, gradient and largest nodal force at one iterate.
  struct Point {
    double energy = 0;
    Eigen::VectorXd gradient;
    double residual = 0;
  };
  // The steps of solve(): each returns false when it cannot move x (x and `at` unchanged).
  bool chord_step(const EnergyTerms& terms, const StaticsWorkspace& chord, Positions& x, Point& at,
                  NewtonIterate& log) const;
  // The object's rotation since `chord`'s factorization; the solve with that factor turned by it.
  Mat3 chord_rotation(const StaticsWorkspace& chord, const Positions& x) const;
  // `rounded`: with the factor in single precision (SparseCholesky::solve_preconditioner).
  Eigen::VectorXd solve_rotated(const StaticsWorkspace& chord, const Mat3& R,
                                const Eigen::VectorXd& r, bool rounded) const;
  // Newton's direction at x by conjugate gradients on the true Hessian (or the projected one;
  // assembled into `ws`, not factored), preconditioned with `chord`'s factorization, to a
  // residual of at most `target`; empty when they do not converge within krylov_iterations
  // products or meet non-positive curvature (log.negative_curvature then says so). `exact`: a
  // cold solve's stand-in for a Newton step (StaticsOptions::cold_krylov_steps), solved in
  // double precision and given up as soon as its rate shows the target out of reach.
  Eigen::VectorXd krylov_direction(const EnergyTerms& terms, StaticsWorkspace& ws,
                                   const StaticsWorkspace& chord, const Positions& x,
                                   const Eigen::VectorXd& g, double target, bool exact,
                                   bool projected, NewtonIterate& log) const;
  // A Krylov step with `chord`'s factorization (see krylov_direction), on the projected Hessian
  // where the true one shows negative curvature; false when neither gives an accepted step.
  bool krylov_step(const EnergyTerms& terms, StaticsWorkspace& ws, const StaticsWorkspace& chord,
                   double target, bool exact, Positions& x, Point& at, NewtonIterate& log) const;
  // Empty when not even the projected Hessian factors, or when `stop` asks before it is tried.
  // The true Hessian is tried first unless log.negative_curvature says it is indefinite.
  // `assembled`: ws's assembler already holds the true Hessian at x.
  Eigen::VectorXd newton_direction(const EnergyTerms& terms, StaticsWorkspace& ws,
                                   const Positions& x, const Eigen::VectorXd& g, NewtonIterate& log,
                                   int& factorizations, bool assembled,
                                   const StopRequest& stop) const;
  // solve() in phases; Run is the state they share (statics.cpp).
  struct Run;
  // How an iteration ended: a step taken (logged), the watchdog went back (its own log entry),
  // or the solve ended (run.result says how).
  enum class Outcome { Stepped, WentBack, Ended };
  // The energy, residual and tolerance at the start, and which steps the solve may try; false
  // when the start already ends the solve (run.result says why).
  bool start(const EnergyTerms& terms, Run& run, const StaticsWorkspace* chord) const;
  // Before iteration `it`: the watchdog's verdict (kept, still watched, or gone back), then
  // non-finite, converged, the iteration limit, a stop request; true when the solve ends there.
  bool convergence_test(Run& run, int it) const;
  void watchdog_verdict(Run& run, int it) const;
  // A step without a new factorization: chord, else Krylov; false when neither is taken.
  bool reuse_step(const EnergyTerms& terms, StaticsWorkspace& ws, Run& run,
                  NewtonIterate& log) const;
  // Newton's step: the true Hessian if it factors, else the projected one (the stability check;
  // neither: Singular), then the line search along it.
  Outcome newton_step(const EnergyTerms& terms, StaticsWorkspace& ws, Run& run,
                      NewtonIterate& log) const;
  // The line search along Newton's direction dx: the watchdog's relaxed step in a cold solve's
  // first Newton step; a failure during the watch goes back, otherwise ends the solve.
  Outcome line_search_step(const EnergyTerms& terms, const StaticsWorkspace& ws, Run& run,
                           const Eigen::VectorXd& dx, NewtonIterate& log) const;
  // The first of α = a, a/2, a/4, ... whose state lowers the energy enough, a = min(1,
  // max_step); relaxed: whose state is finite (no element inverted; the watchdog's step).
  bool line_search(const EnergyTerms& terms, const Eigen::VectorXd& dx, Positions& x, Point& at,
                   NewtonIterate& log, bool relaxed) const;
  // The line search's acceptance of a step α·dx from `from` (slope = α ∇E·dx) reaching a state
  // with this energy and gradient: Armijo, or within the energy's round-off a falling force.
  bool decreases(const Point& from, double slope, double alpha, double energy,
                 const Eigen::VectorXd& gradient) const;
  double largest_node_step(const Eigen::VectorXd& dx) const;
  // Energy differences below this are round-off (see the top of this file).
  double energy_noise(double energy) const;
  double max_force(const Eigen::VectorXd& gradient) const;
  void zero_fixed_dofs(Eigen::VectorXd& gradient) const;
  // Assembles and factors at x into ws; projected = use PSD-projected element Hessians;
  // assembled: ws's assembler already holds that Hessian at x (only factors).
  bool factor_at(const EnergyTerms& terms, StaticsWorkspace& ws, const Positions& x, bool projected,
                 bool assembled) const;
  // Why the projected Hessian factor_at just assembled in ws could not be factored.
  std::string singular_reason(const StaticsWorkspace& ws) const;

  int node_count_;
  std::vector<char> fixed_dof_;
  StaticsOptions options_;
};

}  // namespace shapectl
