#pragma once
// The reduced control objective Ô(θ) = O(x̂(θ), θ) (paper eq. 6):
//   w_s · ½ Σ_{i∈S} |x̂ᵢ(θ) − p'ᵢ|²  +  w_c · collision barrier(θ)  +  w_l · joint-limit barrier(θ),
// its gradient by direct sensitivities, by the adjoint method or by finite differences, and
// its least-squares form (residuals and Jacobian) for Gauss–Newton.
#include <chrono>
#include <limits>
#include <optional>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

enum class GradientMethod { Sensitivity, Adjoint, FiniteDifference };

// Everything known about one θ.
struct Evaluation {
  Eigen::VectorXd joints;
  Positions positions;  // x̂(θ)
  StaticsResult statics;
  double shape = 0;         // weighted terms of the objective
  double collision = 0;
  double joint_limits = 0;
  double objective = std::numeric_limits<double>::infinity();
  ShapeError error;
  double min_clearance = std::numeric_limits<double>::infinity();  // m, margin not subtracted
  bool within_limits = true;  // hard limits, no margin
  // A configuration we may hand to a robot.
  bool safe() const { return statics.converged() && min_clearance >= 0 && within_limits; }
};

struct ObjectiveTiming {
  int statics_solves = 0;
  double statics_seconds = 0;
  int gradient_evaluations = 0;
  double gradient_seconds = 0;  // reduced gradients / Jacobians only
};

class ReducedObjective {
 public:
  explicit ReducedObjective(GrippedObject& object);

  // Throws InputError ("targets: targets[k]...", see check_targets) for a node out of range or
  // a position not finite or beyond max_target_distance; the targets are then unchanged.
  void set_targets(ShapeTargets targets);
  const ShapeTargets& targets() const { return targets_; }
  GrippedObject& object() { return object_; }
  int joint_count() const { return object_.joint_count(); }

  // Solves statics at θ from the warm start `x` and scores it. The object's state is then
  // this θ's (what gradient() and least_squares() need).
  // max_newton > 0 caps the Newton iterations (a trial that needs more is not worth it).
  Evaluation evaluate(const Eigen::VectorXd& joints, const Positions& x, int max_newton = 0);
  // True if `e` is a stable equilibrium (the Hessian there positive definite); otherwise
  // marks it Unstable, objective +inf. Optimizers ask before accepting a state: an unstable
  // equilibrium is no shape a robot can hold. The factorization it needs is the one the next
  // gradient reuses, so accepted states cost nothing extra.
  bool confirm_stable(Evaluation& e);
  // Re-scores an evaluation after a target change, without re-solving.
  void rescore(Evaluation& e) const;
  // dÔ/dθ at `at` (re-solved first if the object has since moved elsewhere).
  Eigen::VectorXd gradient(const Evaluation& at, GradientMethod method);
  // Residuals r (½|r|² = Ô) and Jacobian dr/dθ at `at`; `dx_dtheta` receives dx̂/dθ if given.
  void least_squares(const Evaluation& at, Eigen::VectorXd& r, Eigen::MatrixXd& J,
                     Eigen::MatrixXd* dx_dtheta = nullptr);
  // dx̂/dθ at `at` (exact unless `allow_stale`; see StaticsSolver::solve_hessian).
  Eigen::MatrixXd sensitivity(const Evaluation& at, bool allow_stale);

  ObjectiveTiming& timing() { return timing_; }
  double finite_difference_step = 1e-6;  // rad, forward differences (the paper's baseline)
  // Allowed staleness of the factorization reused for sensitivities, metres of the last
  // Newton step (0 = always exact).
  double stale_factor_step = 1e-6;

 private:
  void make_current(const Evaluation& at);
  void score(Evaluation& e) const;
  Eigen::VectorXd shape_gradient_x(const Evaluation& at) const;  // ∂O_shape/∂x, weighted

  GrippedObject& object_;
  ShapeTargets targets_;
  std::optional<CollisionModel> collisions_;
  JointLimits limits_;
  ObjectiveWeights weights_;
  Eigen::VectorXd current_joints_;  // θ of the object's last solve
  Positions current_positions_;
  ObjectiveTiming timing_;
};

}  // namespace shapectl
