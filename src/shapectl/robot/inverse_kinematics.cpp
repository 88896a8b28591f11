#include <shapectl/robot/inverse_kinematics.hpp>

#include <shapectl/robot/joint_limits.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

namespace shapectl {

std::string_view to_string(IkStatus status) {
  switch (status) {
    case IkStatus::Converged: return "converged";
    case IkStatus::NotReached: return "not_reached";
    case IkStatus::Colliding: return "colliding";
    case IkStatus::InvalidInput: return "invalid_input";
  }
  return "invalid_input";
}

namespace {

Eigen::Matrix3d skew(const Vec3& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

struct Bounds {
  Eigen::VectorXd lower, upper;
};

// The hard limits moved inwards by the margin (a limit range narrower than twice the margin
// collapses to its middle).
Bounds inner_bounds(const RobotModel& model, double margin) {
  Bounds b{model.lower_limits(), model.upper_limits()};
  for (int i = 0; i < b.lower.size(); ++i) {
    if (!std::isfinite(b.lower[i]) || !std::isfinite(b.upper[i])) continue;
    const double m = joint_margin(b.lower[i], b.upper[i], margin);
    const double lo = b.lower[i] + m, hi = b.upper[i] - m;
    if (lo <= hi) {
      b.lower[i] = lo;
      b.upper[i] = hi;
    } else {
      b.lower[i] = b.upper[i] = 0.5 * (b.lower[i] + b.upper[i]);
    }
  }
  return b;
}

Eigen::VectorXd clamp(const Eigen::VectorXd& q, const Bounds& b) {
  return q.cwiseMax(b.lower).cwiseMin(b.upper);
}

// Angle between two unit vectors, accurate near 0 and π.
double axis_angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Errors {
  double position = 0;
  double orientation = 0;
  double clearance = std::numeric_limits<double>::infinity();
};

Errors goal_errors(const RobotModel& model, const std::vector<IkGoal>& goals,
                   const IkOptions& options, const Eigen::VectorXd& q) {
  const KinematicsState state = forward_kinematics(model, q);
  Errors e;
  for (const auto& g : goals) {
    const auto& T = state.T_world_link[static_cast<std::size_t>(g.link)];
    e.position = std::max(e.position, (T * g.point_link - g.position_world).norm());
    if (g.rotation_world)
      e.orientation =
          std::max(e.orientation,
                   Eigen::AngleAxisd(T.linear() * g.rotation_world->transpose()).angle());
    else if (g.axis_link)
      e.orientation = std::max(e.orientation, axis_angle(T.linear() * *g.axis_link, g.axis_world));
  }
  if (options.collisions) e.clearance = options.collisions->min_clearance(state);
  return e;
}

bool reached(const Errors& e, const IkOptions& o) {
  return e.position <= o.position_tolerance && e.orientation <= o.orientation_tolerance;
}

struct Start {
  Eigen::VectorXd joints;
  int iterations = 0;
};

// One Levenberg–Marquardt run from q, projected onto the bounds.
Start run_lm(const RobotModel& model, const std::vector<IkGoal>& goals, const IkOptions& options,
             const Bounds& bounds, Eigen::VectorXd q) {
  Eigen::VectorXd r, r_trial;
  Eigen::MatrixXd J;
  ik_residuals(model, goals, options, q, r, &J);
  double cost = 0.5 * r.squaredNorm();
  double lambda = 1e-3;
  Start s;
  for (; s.iterations < options.max_iterations; ++s.iterations) {
    const Errors e = goal_errors(model, goals, options, q);
    if (reached(e, options) && e.clearance > 0) break;
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool accepted = false;
    while (lambda < 1e10) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal().array() += lambda * (1 + JtJ.diagonal().array());
      Eigen::VectorXd step = -A.ldlt().solve(g);
      if (!step.allFinite()) break;
      const double largest = step.cwiseAbs().maxCoeff();
      if (largest > options.max_step) step *= options.max_step / largest;
      const Eigen::VectorXd trial = clamp(q + step, bounds);
      ik_residuals(model, goals, options, trial, r_trial);
      const double trial_cost = 0.5 * r_trial.squaredNorm();
      if (trial_cost < cost) {
        q = trial;
        accepted = true;
        lambda = std::max(lambda / 3, 1e-9);
        break;
      }
      lambda *= 4;
    }
    if (!accepted) break;  // stationary: no step lowers the cost
    ik_residuals(model, goals, options, q, r, &J);
    const double previous = cost;
    cost = 0.5 * r.squaredNorm();
    if (previous - cost < 1e-16 * (1 + previous)) break;
  }
  s.joints = q;
  return s;
}

}  // namespace

void ik_residuals(const RobotModel& model, const std::vector<IkGoal>& goals,
                  const IkOptions& options, const Eigen::VectorXd& joints,
                  Eigen::VectorXd& residuals, Eigen::MatrixXd* jacobian) {
  const int n = model.active_count();
  int rows = 0;
  for (const auto& g : goals) rows += g.rotation_world ? 12 : g.axis_link ? 6 : 3;
  const int collision_rows = options.collisions ? options.collisions->pair_count() : 0;
  residuals.resize(rows + collision_rows);
  if (jacobian) jacobian->setZero(rows + collision_rows, n);
  const KinematicsState state = forward_kinematics(model, joints);
  int row = 0;
  for (const auto& g : goals) {
    const auto& T = state.T_world_link[static_cast<std::size_t>(g.link)];
    const Vec3 p = T * g.point_link;
    residuals.segment<3>(row) = p - g.position_world;
    if (jacobian) point_jacobian_world(model, state, g.link, p, jacobian->block(row, 0, 3, n));
    row += 3;
    if (!g.rotation_world && g.axis_link) {
      // w (R a − a*); d(R a)/dθ_j = ω_j × (R a) for a revolute joint with world axis ω_j.
      const Vec3 axis = T.linear() * *g.axis_link;
      residuals.segment<3>(row) = g.orientation_weight * (axis - g.axis_world);
      if (jacobian)
        for (const auto& entry : model.jacobian_entries(g.link)) {
          const Joint& joint = model.joints()[static_cast<std::size_t>(entry.joint)];
          if (joint.type == JointType::Prismatic) continue;
          jacobian->block(row, entry.column, 3, 1) +=
              g.orientation_weight * entry.scale *
              state.joint_axes_world[static_cast<std::size_t>(entry.joint)].cross(axis);
        }
      row += 3;
      continue;
    }
    if (!g.rotation_world) continue;
    // w (R − R*), column-major; dR/dθ_j = [ω_j]× R for a revolute joint with world axis ω_j.
    const Eigen::Matrix3d R = T.linear();
    const Eigen::Matrix3d D = g.orientation_weight * (R - *g.rotation_world);
    residuals.segment<9>(row) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(D.data());
    if (jacobian) {
      for (const auto& entry : model.jacobian_entries(g.link)) {
        const Joint& joint = model.joints()[static_cast<std::size_t>(entry.joint)];
        if (joint.type == JointType::Prismatic) continue;
        const Eigen::Matrix3d dR =
            g.orientation_weight * entry.scale *
            skew(state.joint_axes_world[static_cast<std::size_t>(entry.joint)]) * R;
        jacobian->block(row, entry.column, 9, 1) +=
            Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dR.data());
      }
    }
    row += 9;
  }
  if (collision_rows > 0) {
    Eigen::VectorXd rc;
    Eigen::MatrixXd Jc;
    options.collisions->residuals(model, state, rc, jacobian ? &Jc : nullptr);
    const double w = std::sqrt(options.collision_weight);
    residuals.segment(row, collision_rows) = w * rc;
    if (jacobian) jacobian->block(row, 0, collision_rows, n) = w * Jc;
  }
}

IkResult solve_inverse_kinematics(const RobotModel& model, const std::vector<IkGoal>& goals,
                                  const Eigen::VectorXd& joints0, const IkOptions& options) {
  IkResult result;
  if (joints0.size() != model.active_count() || !joints0.allFinite()) {
    result.reason =
        "start joints: expected " + std::to_string(model.active_count()) + " finite values";
    return result;
  }
  for (std::size_t k = 0; k < goals.size(); ++k)
    if (goals[k].link < 0 || goals[k].link >= model.link_count() ||
        !goals[k].position_world.allFinite() || !goals[k].point_link.allFinite()) {
      result.reason = "goal " + std::to_string(k) + ": unknown link or non-finite point";
      return result;
    } else if (goals[k].axis_link && !(std::abs(goals[k].axis_link->norm() - 1) < 1e-9 &&
                                       std::abs(goals[k].axis_world.norm() - 1) < 1e-9)) {
      result.reason = "goal " + std::to_string(k) + ": an axis that is not a unit vector";
      return result;
    }
  const Bounds bounds = inner_bounds(model, options.joint_limit_margin);
  std::mt19937 rng(options.seed);
  // Best so far: collision-free first, then smallest position error.
  bool have_best = false;
  Errors best_errors;
  auto better = [](const Errors& a, const Errors& b) {
    const bool a_free = a.clearance > 0, b_free = b.clearance > 0;
    if (a_free != b_free) return a_free;
    return a.position + a.orientation < b.position + b.orientation;
  };
  // Joints that move no goal's link (a finger named active) keep their start in every restart:
  // they cannot help, and drawing them would change the search for the joints that can.
  std::vector<char> moves_a_goal(static_cast<std::size_t>(model.active_count()), 0);
  for (const auto& g : goals)
    for (const auto& entry : model.jacobian_entries(g.link))
      moves_a_goal[static_cast<std::size_t>(entry.column)] = 1;
  for (int start = 0; start <= options.restarts; ++start) {
    Eigen::VectorXd q = clamp(joints0, bounds);
    if (start > 0)
      for (int i = 0; i < q.size(); ++i) {
        if (!moves_a_goal[static_cast<std::size_t>(i)]) continue;
        const double lo = std::isfinite(bounds.lower[i]) ? bounds.lower[i] : -M_PI;
        const double hi = std::isfinite(bounds.upper[i]) ? bounds.upper[i] : M_PI;
        q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
    const Start s = run_lm(model, goals, options, bounds, q);
    result.iterations += s.iterations;
    result.starts = start + 1;
    const Errors e = goal_errors(model, goals, options, s.joints);
    if (!have_best || better(e, best_errors)) {
      have_best = true;
      best_errors = e;
      result.joints = s.joints;
    }
    if (reached(e, options) && e.clearance > 0) break;
  }
  result.position_error = best_errors.position;
  result.orientation_error = best_errors.orientation;
  result.min_clearance = best_errors.clearance;
  std::ostringstream why;
  if (!reached(best_errors, options)) {
    result.status = IkStatus::NotReached;
    why << "goals not reached after " << result.starts << " starts: position error "
        << best_errors.position << " m, orientation error " << best_errors.orientation << " rad";
  } else if (!(best_errors.clearance > 0)) {
    result.status = IkStatus::Colliding;
    why << "goals reached only in self-collision (clearance " << best_errors.clearance << " m)";
  } else {
    result.status = IkStatus::Converged;
    why << "position error " << best_errors.position << " m after " << result.iterations
        << " iterations, " << result.starts << " start(s)";
  }
  result.reason = why.str();
  return result;
}

}  // namespace shapectl
