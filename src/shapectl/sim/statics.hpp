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
#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/sim/hessian_assembler.hpp>
#include <shapectl/sim/sparse_cholesky.hpp>

namespace shapectl {

// Unstable: an equilibrium where the Hessian is not positive definite (a saddle, e.g. the
// bar at the tipping point of a buckle); reported only by StaticsSolver::confirm_stable.
enum class StaticsStatus { Converged, NotConverged, Inverted, Singular, Unstable };
const char* to_string(StaticsStatus status);

struct StaticsOptions {
  double force_tolerance = 1e-6;  // N: converged when every free node's force is below this
  // N: the force round-off leaves at the equilibrium; the effective tolerance is never lower.
  double force_roundoff = 0;
  // J: energy differences below this are round-off (at least 1e-12 |E|).
  double energy_roundoff = 0;
  int max_iterations = 100;
  // Try a step with the last true-Hessian factorization before factoring anew (see newton()).
  bool chord_steps = true;
  // Which sparse Cholesky; by default chosen by system size (SparseCholesky::choose).
  std::optional<SparseCholesky::Backend> backend;
};

struct NewtonIterate {
  int iteration = 0;
  double residual = 0;       // largest nodal force norm at the start of the iteration, N
  double energy = 0;         // J
  double step = 0;           // largest nodal displacement of the accepted step, m
  double step_length = 0;    // line-search factor α
  bool projected = false;    // the PSD-projected Hessian was used
  bool chord = false;        // an earlier factorization was reused (no new one)
};

struct StaticsResult {
  StaticsStatus status = StaticsStatus::NotConverged;
  std::string reason;  // why it stopped, e.g. "residual 3e-2 N after 50 iterations"
  int iterations = 0;
  double residual = 0;  // largest nodal force norm at the returned state, N
  double energy = 0;
  std::vector<NewtonIterate> log;
  bool converged() const { return status == StaticsStatus::Converged; }
};

class StaticsSolver {
 public:
  // terms: the energy (not owned; must outlive the solver). fixed_node[i]: node i keeps the
  // position it has in x (Dirichlet). Sizes: n nodes, 3n unknowns.
  StaticsSolver(int node_count, std::vector<const EnergyTerm*> terms, std::vector<char> fixed_node,
                StaticsOptions options = {});
  // Starts from x (warm start) and overwrites it with the equilibrium or the last iterate.
  // max_iterations > 0 overrides the options' limit for this call (optimizer trials).
  StaticsResult solve(Positions& x, int max_iterations = 0);

  // Total energy and its gradient (fixed dofs zeroed) at x.
  double energy(const Positions& x) const;
  Eigen::VectorXd gradient(const Positions& x) const;
  // Solves H(x) Y = rhs with the true Hessian at x, rows of fixed dofs zero. Reuses the
  // factorization when it is of the true Hessian at exactly this x, or — when x is the result
  // of the last solve and `stale_step` > 0 — at a state from which no node of x is more than
  // `stale_step` metres away (an error of that order in H; it saves a factorization per
  // optimizer iteration).
  Eigen::MatrixXd solve_hessian(const Positions& x, const Eigen::MatrixXd& rhs,
                                double stale_step = 0);
  // Whether the true Hessian at x is positive definite, i.e. the equilibrium x is stable.
  // Leaves that factorization for solve_hessian (same reuse rule), so checking an accepted
  // state costs nothing extra.
  bool hessian_positive_definite(const Positions& x, double stale_step = 0);
  // The true Hessian at x, lower triangle, fixed dofs eliminated (for tests and tools).
  SparseMatrix hessian(const Positions& x);

  const std::vector<char>& fixed_dof() const { return assembler_.fixed_dof(); }
  const StaticsOptions& options() const { return options_; }
  void set_force_tolerance(double tolerance) { options_.force_tolerance = tolerance; }
  // The tolerance Newton stops at: the larger of force_tolerance and force_roundoff.
  double effective_tolerance() const { return std::max(options_.force_tolerance, options_.force_roundoff); }
  void set_chord_steps(bool on) { options_.chord_steps = on; }
  int factorizations() const { return factorizations_; }

 private:
  StaticsResult newton(Positions& x, int max_iterations);
  double max_force(const Eigen::VectorXd& gradient) const;
  // Assembles and factors at x; projected = use PSD-projected element Hessians.
  bool factor_at(const Positions& x, bool projected);
  // Why the projected Hessian factor_at just assembled could not be factored, with its
  // conditioning.
  std::string singular_reason() const;

  int node_count_;
  std::vector<const EnergyTerm*> terms_;
  StaticsOptions options_;
  HessianAssembler assembler_;
  SparseCholesky cholesky_;
  Triplets triplets_;
  bool analyzed_ = false;
  // What the current factor is of: the true Hessian at factor_x_, or not usable.
  bool factor_is_true_ = false;
  Positions factor_x_;
  int factorizations_ = 0;
  // The result of the last solve and how far its last Newton step (from factor_x_) moved.
  Positions solved_x_;
  double last_step_from_factor_ = std::numeric_limits<double>::infinity();
};

}  // namespace shapectl
