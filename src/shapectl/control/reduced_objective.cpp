#include <shapectl/control/reduced_objective.hpp>

#include <cmath>

namespace shapectl {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

ReducedObjective::ReducedObjective(GrippedObject& object)
    : object_(object),
      limits_(object.robot(), object.scene().robot->joint_limit_margin,
              object.scene().robot->joint_limit_stiffness),
      weights_(object.scene().weights) {
  if (object.scene().robot->collisions) collisions_ = *object.scene().robot->collisions;
}

void ReducedObjective::set_targets(ShapeTargets targets) {
  check_targets(targets, object_.node_count(), "targets");
  targets_ = std::move(targets);
}

void ReducedObjective::score(Evaluation& e) const {
  e.error = shape_error(targets_, e.positions);
  double sum = 0;
  for (int k = 0; k < targets_.size(); ++k)
    sum += (e.positions.segment<3>(3 * targets_.nodes[k]) - targets_.positions[k]).squaredNorm();
  e.shape = weights_.shape * 0.5 * sum;
  e.objective = e.statics.converged() ? e.shape + e.collision + e.joint_limits
                                      : std::numeric_limits<double>::infinity();
}

void ReducedObjective::rescore(Evaluation& e) const { score(e); }

Evaluation ReducedObjective::evaluate(const Eigen::VectorXd& joints, const Positions& x, int max_newton) {
  Evaluation e;
  e.joints = joints;
  e.positions = x;
  const auto t0 = Clock::now();
  e.statics = object_.solve(joints, e.positions, max_newton);
  timing_.statics_seconds += seconds_since(t0);
  ++timing_.statics_solves;
  current_joints_ = joints;
  current_positions_ = e.positions;

  const KinematicsState& state = object_.kinematics();
  if (collisions_) {
    e.min_clearance = collisions_->min_clearance(state);
    e.collision = weights_.collision * collisions_->value(object_.robot(), state);
  }
  e.joint_limits = weights_.joint_limits * limits_.value(joints);
  e.within_limits = limit_violations(object_.robot(), state.joints).empty();
  score(e);
  return e;
}

bool ReducedObjective::confirm_stable(Evaluation& e) {
  if (!e.statics.converged()) return false;
  make_current(e);
  if (object_.statics().solver().hessian_positive_definite(e.positions, stale_factor_step)) return true;
  e.statics.status = StaticsStatus::Unstable;
  e.statics.reason = "unstable equilibrium: the Hessian there is not positive definite";
  score(e);
  return false;
}

void ReducedObjective::make_current(const Evaluation& at) {
  if (current_joints_.size() == at.joints.size() && current_joints_ == at.joints &&
      current_positions_ == at.positions)
    return;
  Positions x = at.positions;
  object_.solve(at.joints, x);  // already at equilibrium: no Newton step, same x
  current_joints_ = at.joints;
  current_positions_ = x;
}

Eigen::VectorXd ReducedObjective::shape_gradient_x(const Evaluation& at) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(at.positions.size());
  for (int k = 0; k < targets_.size(); ++k) {
    const int i = targets_.nodes[k];
    g.segment<3>(3 * i) += weights_.shape * (at.positions.segment<3>(3 * i) - targets_.positions[k]);
  }
  return g;
}

Eigen::MatrixXd ReducedObjective::sensitivity(const Evaluation& at, bool allow_stale) {
  make_current(at);
  return object_.statics().solver().solve_hessian(
      at.positions, object_.grips().force_jacobian(object_.node_count()),
      allow_stale ? stale_factor_step : 0.0);
}

Eigen::VectorXd ReducedObjective::gradient(const Evaluation& at, GradientMethod method) {
  const auto t0 = Clock::now();
  Eigen::VectorXd g(joint_count());
  if (method == GradientMethod::FiniteDifference) {
    // Forward differences of the full reduced objective, each a warm-started statics solve.
    for (int j = 0; j < joint_count(); ++j) {
      Eigen::VectorXd theta = at.joints;
      theta[j] += finite_difference_step;
      const Evaluation e = evaluate(theta, at.positions);
      g[j] = (e.objective - at.objective) / finite_difference_step;
    }
    timing_.statics_solves -= joint_count();  // counted as gradient work, not statics
  } else {
    make_current(at);
    const Eigen::VectorXd dO_dx = shape_gradient_x(at);
    if (method == GradientMethod::Adjoint) {
      const Eigen::VectorXd lambda = object_.statics().solver().solve_hessian(
          at.positions, dO_dx, stale_factor_step);
      g = object_.grips().force_jacobian_transpose_times(lambda);
    } else {
      g = sensitivity(at, true).transpose() * dO_dx;
    }
    const KinematicsState& state = object_.kinematics();
    Eigen::VectorXd barrier(joint_count());
    if (collisions_) {
      collisions_->value(object_.robot(), state, &barrier);
      g += weights_.collision * barrier;
    }
    limits_.value(at.joints, &barrier);
    g += weights_.joint_limits * barrier;
  }
  timing_.gradient_seconds += seconds_since(t0);
  ++timing_.gradient_evaluations;
  return g;
}

void ReducedObjective::least_squares(const Evaluation& at, Eigen::VectorXd& r, Eigen::MatrixXd& J,
                                     Eigen::MatrixXd* dx_dtheta) {
  const auto t0 = Clock::now();
  const Eigen::MatrixXd dx = sensitivity(at, true);
  const KinematicsState& state = object_.kinematics();
  const int m = joint_count();
  Eigen::VectorXd r_collision, r_limits;
  Eigen::MatrixXd J_collision, J_limits;
  if (collisions_) collisions_->residuals(object_.robot(), state, r_collision, &J_collision);
  limits_.residuals(at.joints, r_limits, &J_limits);
  const int n_shape = 3 * targets_.size();
  r.resize(n_shape + r_collision.size() + r_limits.size());
  J.resize(r.size(), m);
  const double ws = std::sqrt(weights_.shape);
  for (int k = 0; k < targets_.size(); ++k) {
    const int i = targets_.nodes[k];
    r.segment<3>(3 * k) = ws * (at.positions.segment<3>(3 * i) - targets_.positions[k]);
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
  timing_.gradient_seconds += seconds_since(t0);
  ++timing_.gradient_evaluations;
}

}  // namespace shapectl
