#pragma once
// Joint-space optimizers for the reduced objective, one iteration at a time so a controller
// can interleave target edits. Every trial θ re-solves statics warm-started from the current
// (accepted) state, which keeps the object on its equilibrium branch (paper Fig. 8). Starting
// from a safe state (converged, collision-free, within limits), only safe states are accepted.
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/control/reduced_objective.hpp>

namespace shapectl {

enum class StepOutcome {
  Improved,   // a better θ was accepted into `current`
  Converged,  // stationary: no further progress expected
  Stuck,      // no acceptable step found (e.g. every trial collides or statics failed)
  OutOfTime,  // the budget ran out (out_of_time) before a step was accepted
};
const char* to_string(StepOutcome outcome);

// An optimizer object is the explicit state of one run (curvature pairs, damping): step()
// continues from the previous step of the same object, reset() forgets it.
class Optimizer {
 public:
  virtual ~Optimizer() = default;
  virtual std::string name() const = 0;
  virtual StepOutcome step(const ReducedObjective& objective, Evaluation& current) = 0;
  // Forget accumulated curvature/damping, e.g. after the targets changed.
  virtual void reset() = 0;
  // Why the last step that did not improve (converged or stuck) ended there, in words with
  // numbers, for a best effort's reason; empty when the optimizer keeps no account.
  virtual std::string why_stopped() const { return {}; }
  // A trust region: the joints no trial may leave, per joint (rad). Empty: none (the paper's
  // method). Trials are projected into it (the current joints must be inside); the controller
  // holds what the feedback may do with it (control/controller.hpp).
  struct JointBox {
    Eigen::VectorXd lower, upper;
  };
  std::optional<JointBox> box;
  // Asked before every statics trial and every gradient; true ends the step there, so a budget
  // is overrun by at most one statics solve or gradient. Empty: no budget.
  std::function<bool()> out_of_time;

 protected:
  bool budget_spent() const { return out_of_time && out_of_time(); }
  // `joints` projected into the box (unchanged without one).
  Eigen::VectorXd held(const Eigen::VectorXd& joints) const {
    return box ? Eigen::VectorXd(joints.cwiseMax(box->lower).cwiseMin(box->upper)) : joints;
  }
};

enum class OptimizerKind { GaussNewton, Lbfgs };
// "gauss-newton", "lbfgs": the names the CLI, bench and server use.
const char* to_string(OptimizerKind kind);
bool parse(std::string_view name, OptimizerKind* kind);
std::vector<std::string> optimizer_names();

// Levenberg–Marquardt on the residual form; J from direct sensitivities plus the barrier
// residual Jacobians. The next equilibrium is predicted with dx̂/dθ·Δθ before Newton starts.
class GaussNewton : public Optimizer {
 public:
  std::string name() const override { return to_string(OptimizerKind::GaussNewton); }
  StepOutcome step(const ReducedObjective& objective, Evaluation& current) override;
  void reset() override { damping_ = kInitialDamping; }
  std::string why_stopped() const override { return stopped_; }
  double max_step = 0.3;  // rad, largest joint change per trial

 private:
  // λ after a target change, relative to the largest diagonal entry of JᵀJ. Measured with
  // `shapectl bench` on the YuMi bar: 1e-4 lets the first step run into the bar's nonlinearity
  // (statics trials of 20+ Newton steps, rejections: p90 2.5x the median); 1e-2 is so timid
  // that the buckling case creeps along the bifurcation for seconds; 3e-3 is best for both.
  static constexpr double kInitialDamping = 3e-3;
  double damping_ = kInitialDamping;
  std::string stopped_;
};

// L-BFGS with a backtracking (Armijo) line search, as in the paper.
class Lbfgs : public Optimizer {
 public:
  explicit Lbfgs(GradientMethod method) : method_(method) {}
  std::string name() const override { return to_string(OptimizerKind::Lbfgs); }
  StepOutcome step(const ReducedObjective& objective, Evaluation& current) override;
  void reset() override;
  int memory = 8;
  double max_step = 0.2;  // rad, largest joint change of a first (unscaled) step

 private:
  GradientMethod method_;
  std::deque<Eigen::VectorXd> s_, y_;
  Eigen::VectorXd gradient_;  // at the current point, if known
  Eigen::VectorXd gradient_at_;
};

std::unique_ptr<Optimizer> make_optimizer(OptimizerKind kind, GradientMethod gradient);

// Solves statics at `joints`, trying the prediction first and falling back to the plain warm
// start (`from`'s positions) if the predicted state is inverted. The fallback is skipped (the
// inverted evaluation returned) if `out_of_time` says the budget is spent. Chord steps use `from`'s
// factorization (the state both starts came from).
Evaluation evaluate_predicted(const ReducedObjective& objective, const Eigen::VectorXd& joints,
                              const Evaluation& from, const Positions& predicted,
                              const std::function<bool()>& out_of_time = {});

}  // namespace shapectl
