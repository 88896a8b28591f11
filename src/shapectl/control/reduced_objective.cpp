#include <shapectl/control/reduced_objective.hpp>

#include <cmath>

#include <shapectl/enum_names.hpp>

namespace shapectl {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
constexpr auto kGradientMethods =
    enum_names<GradientMethod>(std::pair{GradientMethod::Sensitivity, "sensitivity"},
                               std::pair{GradientMethod::Adjoint, "adjoint"},
                               std::pair{GradientMethod::FiniteDifference, "finite-difference"});
}  // namespace

const char* to_string(GradientMethod method) { return kGradientMethods.name(method); }

bool parse(std::string_view name, GradientMethod* method) {
  return kGradientMethods.parse(name, method);
}

std::vector<std::string> gradient_names() { return kGradientMethods.names(); }

namespace {
const Eigen::VectorXd kNoJoints;
const StaticsResult kNotSolved;
}  // namespace

const Eigen::VectorXd& Evaluation::joints() const { return state ? state->joints() : kNoJoints; }
const Positions& Evaluation::positions() const { return state ? state->positions() : kNoJoints; }
const StaticsResult& Evaluation::statics() const { return state ? state->statics() : kNotSolved; }

ReducedObjective::ReducedObjective(const GrippedObject& object, ShapeTargets targets,
                                   ObjectiveOptions options,
                                   std::shared_ptr<WorkspacePool> workspaces)
    : object_(&object),
      targets_(std::move(targets)),
      options_(options),
      limits_(object.robot(), object.scene().robot->joint_limit_margin,
              object.scene().robot->joint_limit_stiffness),
      weights_(object.scene().weights),
      counters_(std::make_shared<TimingCounters>()),
      workspaces_(workspaces ? std::move(workspaces) : WorkspacePool::create()) {
  check_targets(targets_, object.node_count(), "targets");
  if (object.scene().robot->collisions) collisions_ = *object.scene().robot->collisions;
}

ReducedObjective ReducedObjective::with_targets(ShapeTargets targets) const {
  check_targets(targets, object_->node_count(), "targets");
  ReducedObjective copy = *this;
  copy.targets_ = std::move(targets);
  return copy;
}

ObjectiveTiming ReducedObjective::timing() const {
  std::lock_guard lock(counters_->mutex);
  return counters_->timing;
}

void ReducedObjective::count_statics(double seconds) const {
  std::lock_guard lock(counters_->mutex);
  ++counters_->timing.statics_solves;
  counters_->timing.statics_seconds += seconds;
}

void ReducedObjective::count_gradient(double seconds) const {
  std::lock_guard lock(counters_->mutex);
  ++counters_->timing.gradient_evaluations;
  counters_->timing.gradient_seconds += seconds;
}

void ReducedObjective::score(Evaluation& e) const {
  e.error = shape_error(targets_, e.positions());
  double sum = 0;
  for (int k = 0; k < targets_.size(); ++k)
    sum += (e.positions().segment<3>(3 * targets_.nodes[k]) - targets_.positions[k]).squaredNorm();
  e.shape = weights_.shape * 0.5 * sum;
  e.objective = e.statics().converged() ? e.shape + e.collision + e.joint_limits
                                        : std::numeric_limits<double>::infinity();
}

void ReducedObjective::rescore(Evaluation& e) const { score(e); }

Evaluation ReducedObjective::describe(ObjectState state) const {
  Evaluation e;
  e.state = std::make_shared<ObjectState>(std::move(state));
  const KinematicsState& kinematics = e.state->kinematics();
  if (collisions_) {
    e.min_clearance = collisions_->min_clearance(kinematics);
    e.collision = weights_.collision * collisions_->value(object_->robot(), kinematics);
  }
  e.joint_limits = weights_.joint_limits * limits_.value(e.joints());
  e.within_limits = limit_violations(object_->robot(), kinematics.joints).empty();
  score(e);
  return e;
}

Evaluation ReducedObjective::evaluate(const Eigen::VectorXd& joints, const Positions& x,
                                      int max_newton, const Evaluation* from,
                                      const StopRequest& stop) const {
  const auto t0 = Clock::now();
  const ObjectState* chord = from && options_.chord_steps ? from->state.get() : nullptr;
  // x is clear of the obstacles where `from`'s joints put them (its equilibrium, or carried
  // from it): obstacles on links are swept on from there.
  ObjectState state =
      from ? object_->solve_along(from->joints(), joints, x, max_newton, chord, stop, workspaces_)
           : object_->solve_from(joints, x, max_newton, chord, stop, workspaces_);
  count_statics(seconds_since(t0));
  return describe(std::move(state));
}

bool ReducedObjective::confirm_stable(Evaluation& e) const {
  if (!e.statics().converged()) return false;
  if (object_->confirm_stable(*e.state, options_.stale_factor_step)) return true;
  score(e);
  return false;
}

Eigen::VectorXd ReducedObjective::shape_gradient_x(const Evaluation& at) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(at.positions().size());
  for (int k = 0; k < targets_.size(); ++k) {
    const int i = targets_.nodes[k];
    g.segment<3>(3 * i) +=
        weights_.shape * (at.positions().segment<3>(3 * i) - targets_.positions[k]);
  }
  return g;
}

Eigen::MatrixXd ReducedObjective::sensitivity(Evaluation& at, bool allow_stale) const {
  return object_->sensitivity(*at.state, allow_stale ? options_.stale_factor_step : 0.0);
}

Eigen::VectorXd ReducedObjective::gradient(Evaluation& at, GradientMethod method) const {
  const auto t0 = Clock::now();
  Eigen::VectorXd g(joint_count());
  if (method == GradientMethod::FiniteDifference) {
    // Forward differences of the full reduced objective, each a warm-started statics solve
    // (counted as gradient work, not statics).
    const double h = options_.finite_difference_step;
    for (int j = 0; j < joint_count(); ++j) {
      Eigen::VectorXd theta = at.joints();
      theta[j] += h;
      const ObjectState* chord = options_.chord_steps ? at.state.get() : nullptr;
      const Evaluation e = describe(
          object_->solve_along(at.joints(), theta, at.positions(), 0, chord, {}, workspaces_));
      g[j] = (e.objective - at.objective) / h;
    }
  } else {
    const Eigen::VectorXd dO_dx = shape_gradient_x(at);
    if (method == GradientMethod::Adjoint)
      g = object_->adjoint(*at.state, dO_dx, options_.stale_factor_step);
    else g = sensitivity(at, true).transpose() * dO_dx;
    const KinematicsState& state = at.state->kinematics();
    Eigen::VectorXd barrier(joint_count());
    if (collisions_) {
      collisions_->value(object_->robot(), state, &barrier);
      g += weights_.collision * barrier;
    }
    limits_.value(at.joints(), &barrier);
    g += weights_.joint_limits * barrier;
  }
  count_gradient(seconds_since(t0));
  return g;
}

void ReducedObjective::least_squares(Evaluation& at, Eigen::VectorXd& r, Eigen::MatrixXd& J,
                                     Eigen::MatrixXd* dx_dtheta) const {
  const auto t0 = Clock::now();
  const Eigen::MatrixXd dx = sensitivity(at, true);
  const KinematicsState& state = at.state->kinematics();
  const int m = joint_count();
  Eigen::VectorXd r_collision, r_limits;
  Eigen::MatrixXd J_collision, J_limits;
  if (collisions_) collisions_->residuals(object_->robot(), state, r_collision, &J_collision);
  limits_.residuals(at.joints(), r_limits, &J_limits);
  const int n_shape = 3 * targets_.size();
  r.resize(n_shape + r_collision.size() + r_limits.size());
  J.resize(r.size(), m);
  const double ws = std::sqrt(weights_.shape);
  for (int k = 0; k < targets_.size(); ++k) {
    const int i = targets_.nodes[k];
    r.segment<3>(3 * k) = ws * (at.positions().segment<3>(3 * i) - targets_.positions[k]);
    J.middleRows<3>(3 * k) = ws * dx.middleRows<3>(3 * i);
  }
  const double wc = std::sqrt(weights_.collision), wl = std::sqrt(weights_.joint_limits);
  if (r_collision.size()) {
    r.segment(n_shape, r_collision.size()) = wc * r_collision;
    J.middleRows(n_shape, r_collision.size()) = wc * J_collision;
  }
  r.tail(r_limits.size()) = wl * r_limits;
  J.bottomRows(r_limits.size()) = wl * J_limits;
  if (dx_dtheta) *dx_dtheta = dx;
  count_gradient(seconds_since(t0));
}

}  // namespace shapectl
