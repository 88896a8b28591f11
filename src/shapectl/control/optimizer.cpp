#include <shapectl/control/optimizer.hpp>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>

#include <shapectl/enum_names.hpp>
#include <shapectl/sim/rigid_motion.hpp>

namespace shapectl {

const char* to_string(StepOutcome outcome) {
  switch (outcome) {
    case StepOutcome::Improved: return "improved";
    case StepOutcome::Converged: return "converged";
    case StepOutcome::Stuck: return "stuck";
    case StepOutcome::OutOfTime: return "out of time";
  }
  return "?";
}

namespace {
constexpr auto kOptimizerKinds =
    enum_names<OptimizerKind>(std::pair{OptimizerKind::GaussNewton, "gauss-newton"},
                              std::pair{OptimizerKind::Lbfgs, "lbfgs"});
}  // namespace

const char* to_string(OptimizerKind kind) { return kOptimizerKinds.name(kind); }

bool parse(std::string_view name, OptimizerKind* kind) { return kOptimizerKinds.parse(name, kind); }

std::vector<std::string> optimizer_names() { return kOptimizerKinds.names(); }

namespace {
// A trial may replace the current state if it is at least as safe and strictly better (a
// non-finite objective is neither).
bool acceptable(const Evaluation& trial, const Evaluation& current, double required_objective) {
  if (!trial.statics().converged() || !std::isfinite(trial.objective)) return false;
  if (current.safe() && !trial.safe()) return false;
  return trial.objective < required_objective;
}

// A decrease too small to matter (relative 1e-4, or an objective below 1e-16 m², i.e. errors
// of nanometres): stop instead of creeping.
bool negligible(double before, double after) {
  return before - after <= 1e-4 * std::abs(before) || after <= 1e-16;
}
}  // namespace

// A trial whose statics need many Newton steps is far outside the linear model: better
// rejected (and the step shortened) than solved at length.
constexpr int kTrialNewtonLimit = 25;

Evaluation evaluate_predicted(const ReducedObjective& objective, const Eigen::VectorXd& joints,
                              const Evaluation& from, const Positions& predicted,
                              const std::function<bool()>& out_of_time) {
  Evaluation e = objective.evaluate(joints, predicted, kTrialNewtonLimit, &from, out_of_time);
  if (e.statics().status == StaticsStatus::Inverted && e.statics().iterations == 0 &&
      !(out_of_time && out_of_time()))
    e = objective.evaluate(joints, from.positions(), kTrialNewtonLimit, &from,
                           out_of_time);  // the prediction itself inverted
  return e;
}

StepOutcome GaussNewton::step(const ReducedObjective& objective, Evaluation& current) {
  // At an equilibrium whose objective overflowed (or is NaN) no trial can be "better" and the
  // derivatives are meaningless. (An unconverged state scores +inf by design: steps may leave it.)
  if (current.statics().converged() && !std::isfinite(current.objective)) return StepOutcome::Stuck;
  if (budget_spent()) return StepOutcome::OutOfTime;
  Eigen::VectorXd r;
  Eigen::MatrixXd J, dx;
  objective.least_squares(current, r, J, &dx);
  // Nothing to linearize around: no step is possible (and none is "converged").
  if (!r.allFinite() || !J.allFinite() || !dx.allFinite()) return StepOutcome::Stuck;
  const Eigen::VectorXd g = J.transpose() * r;
  if (!g.allFinite()) return StepOutcome::Stuck;
  if (g.cwiseAbs().maxCoeff() <= 1e-14 + 1e-10 * r.squaredNorm()) return StepOutcome::Converged;
  const Eigen::MatrixXd A = J.transpose() * J;
  // Damping λ·max(diag JᵀJ)·I, not Marquardt's diag(JᵀJ): a 7-joint arm has self-motions
  // that barely move the object, and scaling by their tiny diagonal would let them run away.
  const double scale = std::max(A.diagonal().maxCoeff(), 1e-18);
  // The trials this step refused, by why: for the words of a stop.
  int no_equilibrium = 0, unsafe = 0, worse = 0;
  const auto stop = [&](StepOutcome outcome, double step) {
    char head[48] = "no step accepted", text[200];
    if (step > 0) std::snprintf(head, sizeof head, "the last step was %.2g rad", step);
    std::snprintf(text, sizeof text,
                  "%s; longer trials refused: %d without a stable equilibrium within %d Newton "
                  "steps, %d into a collision or limit, %d worse",
                  head, no_equilibrium, kTrialNewtonLimit, unsafe, worse);
    stopped_ = text;
    return outcome;
  };
  stopped_.clear();
  for (int attempt = 0; attempt < 12; ++attempt) {
    if (budget_spent()) return StepOutcome::OutOfTime;
    Eigen::MatrixXd damped = A;
    damped.diagonal().array() += damping_ * scale;
    Eigen::VectorXd delta = damped.ldlt().solve(-g);
    const double largest = delta.cwiseAbs().maxCoeff();
    if (!std::isfinite(largest)) return StepOutcome::Stuck;
    if (largest < 1e-12) return StepOutcome::Converged;
    if (largest > max_step) delta *= max_step / largest;
    if (box) {
      // Projected: at the box's face the step loses its outward part. A step that loses all
      // of it is refused like a bad one: more damping turns it towards the projected gradient.
      delta = held(current.joints() + delta) - current.joints();
      if (delta.cwiseAbs().maxCoeff() < 1e-12) {
        damping_ = std::min(damping_ * 4, 1e6);
        continue;
      }
    }
    const Eigen::VectorXd theta = current.joints() + delta;
    // First-order prediction of the new equilibrium with its rotation made finite (a linear
    // one stretches the object), the gripped nodes carried exactly.
    Positions predicted_x = with_finite_rotation(current.positions(), dx * delta);
    objective.object().carry_gripped_nodes(current.joints(), theta, current.positions(),
                                           predicted_x);
    Evaluation trial = evaluate_predicted(objective, theta, current, predicted_x, out_of_time);
    const double predicted = current.objective - 0.5 * (r + J * delta).squaredNorm();
    if (acceptable(trial, current, current.objective) && objective.confirm_stable(trial)) {
      // Gain ratio: how well the linear model predicted the decrease.
      const double gain = (current.objective - trial.objective) / std::max(predicted, 1e-300);
      const bool tiny = negligible(current.objective, trial.objective);
      current = trial;
      if (gain > 0.75) damping_ = std::max(damping_ / 3, 1e-9);
      else if (gain < 0.25) damping_ *= 2;
      return tiny ? stop(StepOutcome::Converged, delta.cwiseAbs().maxCoeff())
                  : StepOutcome::Improved;
    }
    if (!trial.statics().converged()) ++no_equilibrium;
    else if (current.safe() && !trial.safe()) ++unsafe;
    else ++worse;
    damping_ = std::min(damping_ * 4, 1e6);
  }
  return stop(StepOutcome::Stuck, 0);
}

void Lbfgs::reset() {
  s_.clear();
  y_.clear();
  gradient_.resize(0);
}

StepOutcome Lbfgs::step(const ReducedObjective& objective, Evaluation& current) {
  if (current.statics().converged() && !std::isfinite(current.objective))
    return StepOutcome::Stuck;  // as in GaussNewton
  if (gradient_.size() == 0 || gradient_at_ != current.joints()) {
    if (budget_spent()) return StepOutcome::OutOfTime;
    gradient_ = objective.gradient(current, method_);
    gradient_at_ = current.joints();
  }
  // A copy: the accepted step below replaces gradient_.
  const Eigen::VectorXd g = gradient_;
  // A non-finite gradient (e.g. the objective itself overflowed) gives no direction to search.
  if (!g.allFinite()) return StepOutcome::Stuck;
  if (g.cwiseAbs().maxCoeff() <= 1e-14) return StepOutcome::Converged;
  // Two-loop recursion: d = −H g.
  Eigen::VectorXd q = g;
  std::vector<double> alpha(s_.size());
  for (int k = static_cast<int>(s_.size()) - 1; k >= 0; --k) {
    alpha[k] = s_[k].dot(q) / y_[k].dot(s_[k]);
    q -= alpha[k] * y_[k];
  }
  if (!s_.empty()) q *= s_.back().dot(y_.back()) / y_.back().squaredNorm();
  else q *= max_step / g.cwiseAbs().maxCoeff();  // first step: at most max_step rad
  for (std::size_t k = 0; k < s_.size(); ++k) {
    const double beta = y_[k].dot(q) / y_[k].dot(s_[k]);
    q += (alpha[k] - beta) * s_[k];
  }
  Eigen::VectorXd d = -q;
  if (!(g.dot(d) < 0) ||
      !d.allFinite()) {  // not a descent direction: restart from steepest descent
    // Only the curvature pairs are dropped: the gradient at current.joints stays valid (a full
    // reset() here once emptied the gradient this step still reads).
    s_.clear();
    y_.clear();
    d = -g * (max_step / g.cwiseAbs().maxCoeff());
  }
  const double slope = g.dot(d);
  if (!(slope < 0) || !std::isfinite(slope))
    return StepOutcome::Stuck;  // g overflowed in the product
  double t = 1.0;
  for (int k = 0; k < 16; ++k, t *= 0.5) {
    if (budget_spent()) return StepOutcome::OutOfTime;
    const Eigen::VectorXd theta = held(current.joints() + t * d);
    // Armijo along the step taken: the projected one in a box.
    const double decrease = box ? g.dot(theta - current.joints()) : t * slope;
    if (!(decrease < 0)) continue;
    // Warm start from the current shape: carrying the gripped nodes alone (without dx̂/dθ·Δθ
    // for the rest) measured no faster for these short steps.
    Evaluation trial = objective.evaluate(theta, current.positions(), 25, &current, out_of_time);
    if (!acceptable(trial, current, current.objective + 1e-4 * decrease)) continue;
    if (!objective.confirm_stable(trial)) continue;
    const bool tiny = negligible(current.objective, trial.objective);
    const Eigen::VectorXd s = trial.joints() - current.joints();
    current = trial;
    // Out of time: keep the better state; its gradient is computed when (if) a next step comes.
    if (budget_spent()) return tiny ? StepOutcome::Converged : StepOutcome::Improved;
    const Eigen::VectorXd g_new = objective.gradient(current, method_);
    const Eigen::VectorXd y = g_new - g;
    if (y.allFinite() && s.dot(y) > 1e-12 * s.norm() * y.norm()) {
      s_.push_back(s);
      y_.push_back(y);
      if (static_cast<int>(s_.size()) > memory) {
        s_.pop_front();
        y_.pop_front();
      }
    }
    gradient_ = g_new;
    gradient_at_ = current.joints();
    return tiny ? StepOutcome::Converged : StepOutcome::Improved;
  }
  if (s_.empty()) return StepOutcome::Stuck;
  // The curvature model misled the search: retry once along the steepest descent (the gradient
  // at current.joints is kept; nothing moved).
  s_.clear();
  y_.clear();
  return step(objective, current);
}

std::unique_ptr<Optimizer> make_optimizer(OptimizerKind kind, GradientMethod gradient) {
  if (kind == OptimizerKind::Lbfgs) return std::make_unique<Lbfgs>(gradient);
  return std::make_unique<GaussNewton>();
}

}  // namespace shapectl
