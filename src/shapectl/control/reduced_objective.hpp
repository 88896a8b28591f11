#pragma once
// The reduced control objective Ô(θ) = O(x̂(θ), θ) (paper eq. 6):
//   w_s · ½ Σ_{i∈S} |x̂ᵢ(θ) − p'ᵢ|²  +  w_c · collision barrier(θ)  +  w_l · joint-limit barrier(θ),
// its gradient by direct sensitivities, by the adjoint method or by finite differences, and
// its least-squares form (residuals and Jacobian) for Gauss–Newton.
#include <chrono>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

enum class GradientMethod { Sensitivity, Adjoint, FiniteDifference };
// "sensitivity", "adjoint", "finite-difference".
const char* to_string(GradientMethod method);
bool parse(std::string_view name, GradientMethod* method);
std::vector<std::string> gradient_names();

// Everything known about one θ: its solved state and the score. The state (θ, x̂(θ), the
// statics result, the factorization the derivatives at this θ use) is not copied: copies of an
// Evaluation share it, and the accessors read it. A default Evaluation has none and reads as
// empty and not converged.
struct Evaluation {
  std::shared_ptr<ObjectState> state;
  double shape = 0;  // weighted terms of the objective
  double collision = 0;
  double joint_limits = 0;
  double objective = std::numeric_limits<double>::infinity();
  ShapeError error;
  double min_clearance = std::numeric_limits<double>::infinity();  // m, margin not subtracted
  bool within_limits = true;                                       // hard limits, no margin

  const Eigen::VectorXd& joints() const;
  const Positions& positions() const;  // x̂(θ)
  const StaticsResult& statics() const;
  // A configuration we may hand to a robot.
  bool safe() const { return statics().converged() && min_clearance >= 0 && within_limits; }
};

struct ObjectiveTiming {
  int statics_solves = 0;
  double statics_seconds = 0;
  int gradient_evaluations = 0;
  double gradient_seconds = 0;  // reduced gradients / Jacobians only
};

struct ObjectiveOptions {
  double finite_difference_step = 1e-6;  // rad, forward differences (the paper's baseline)
  // Allowed staleness of the factorization reused for sensitivities, metres of the last
  // Newton step (0 = always exact; see GrippedObject::sensitivity).
  double stale_factor_step = 1e-6;
  // Statics from a nearby state first try steps with that state's factorization (see
  // StaticsSolver::solve); off: every solve factors anew (the paper's baseline).
  bool chord_steps = true;
};

// Immutable once made (the targets too: with_targets makes a new one); every call is const and
// takes what it works on explicitly, so threads may share one. Only the timing counters and the
// workspace pool (thread-safe, state side) change.
class ReducedObjective {
 public:
  // The object must outlive this. Throws InputError ("targets: targets[k]...", see
  // check_targets) for a node out of range or a position not finite or beyond
  // max_target_distance.
  // `workspaces`: the pool its states take workspaces from (null: a new one); pass the pool of
  // an objective on an earlier model of the same object to keep its symbolic analyses.
  explicit ReducedObjective(const GrippedObject& object, ShapeTargets targets = {},
                            ObjectiveOptions options = {},
                            std::shared_ptr<WorkspacePool> workspaces = nullptr);
  // The same objective with other targets (checked as above); shares the timing counters and
  // the workspace pool.
  ReducedObjective with_targets(ShapeTargets targets) const;

  const ShapeTargets& targets() const { return targets_; }
  const GrippedObject& object() const { return *object_; }
  const ObjectiveOptions& options() const { return options_; }
  int joint_count() const { return object_->joint_count(); }

  // Solves statics at θ from the warm start `x` (chord steps with `from`'s factorization if
  // given, e.g. the state x came from; x must then be clear of the obstacles where from's
  // joints put them: obstacles on links are swept on from there, GrippedObject::solve) and
  // scores it. max_newton > 0 caps the Newton iterations (a trial that needs more is not worth
  // it); `stop` may end statics early (a time budget: the evaluation is then not converged).
  Evaluation evaluate(const Eigen::VectorXd& joints, const Positions& x, int max_newton = 0,
                      const Evaluation* from = nullptr, const StopRequest& stop = {}) const;
  // True if `e` is a stable equilibrium (the Hessian there positive definite); otherwise
  // marks its state Unstable (GrippedObject::confirm_stable), objective +inf. The
  // factorization it needs is the one the next gradient reuses, so accepted states cost
  // nothing extra.
  bool confirm_stable(Evaluation& e) const;
  // Scores an evaluation (e.g. made under other targets) against this objective's targets.
  void rescore(Evaluation& e) const;
  // The derivatives below factor `at`'s state unless it holds a factorization near enough
  // (ObjectiveOptions::stale_factor_step), hence the non-const evaluation.
  // dÔ/dθ at `at`.
  Eigen::VectorXd gradient(Evaluation& at, GradientMethod method) const;
  // Residuals r (½|r|² = Ô) and Jacobian dr/dθ at `at`; `dx_dtheta` receives dx̂/dθ if given.
  void least_squares(Evaluation& at, Eigen::VectorXd& r, Eigen::MatrixXd& J,
                     Eigen::MatrixXd* dx_dtheta = nullptr) const;
  // dx̂/dθ at `at` (exact unless `allow_stale`).
  Eigen::MatrixXd sensitivity(Evaluation& at, bool allow_stale) const;
  // The pool the states it solves take their workspaces from (shared by with_targets).
  const std::shared_ptr<WorkspacePool>& workspaces() const { return workspaces_; }

  ObjectiveTiming timing() const;

 private:
  struct TimingCounters {
    std::mutex mutex;
    ObjectiveTiming timing;
  };
  void score(Evaluation& e) const;
  Evaluation describe(ObjectState state) const;                  // scores a solved state
  Eigen::VectorXd shape_gradient_x(const Evaluation& at) const;  // ∂O_shape/∂x, weighted
  void count_statics(double seconds) const;
  void count_gradient(double seconds) const;

  const GrippedObject* object_;
  ShapeTargets targets_;
  ObjectiveOptions options_;
  std::optional<CollisionModel> collisions_;
  JointLimits limits_;
  ObjectiveWeights weights_;
  std::shared_ptr<TimingCounters> counters_;
  std::shared_ptr<WorkspacePool> workspaces_;
};

}  // namespace shapectl
