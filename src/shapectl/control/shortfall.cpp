#include <shapectl/control/shortfall.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include <shapectl/control/reach_bound.hpp>
#include <shapectl/enum_names.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {

namespace {
constexpr auto kShortfalls = enum_names<Shortfall>(std::pair{Shortfall::JointLimit, "joint limit"},
                                                   std::pair{Shortfall::Collision, "collision"},
                                                   std::pair{Shortfall::Reach, "reach"},
                                                   std::pair{Shortfall::Buckling, "buckling"});

constexpr double kLimitSlack = 0.01;      // rad beyond the barrier's margin
constexpr double kClearanceSlack = 1e-3;  // m beyond the collision margin
constexpr double kCollisionProbe = 1e-3;  // rad along d
constexpr double kStretched = 0.95;       // of the arm's length
constexpr double kBucklingProbe = 0.02;   // rad along d
constexpr double kSnapFactor = 10;        // × the predicted motion
constexpr double kSnapFloor = 1e-3;       // m

std::string format(const char* pattern, double a, double b = 0) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

// −J_sᵀ r_s: where the targets alone pull the joints.
Eigen::VectorXd shape_descent(const ReducedObjective& objective, Evaluation& at) {
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  objective.least_squares(at, r, J);
  const int rows = 3 * objective.targets().size();
  return -J.topRows(rows).transpose() * r.head(rows);
}

// Joints at a limit that d pushes outward, e.g. "l2 0.3° from its lower limit".
std::string joint_limit(const ReducedObjective& objective, const Evaluation& at,
                        const Eigen::VectorXd& d) {
  const RobotModel& robot = objective.object().robot();
  const double margin = objective.object().scene().robot->joint_limit_margin;
  const Eigen::VectorXd lower = robot.lower_limits(), upper = robot.upper_limits();
  const auto names = robot.active_joint_names();
  const double noise = 0.01 * d.cwiseAbs().maxCoeff();
  std::string out;
  for (int j = 0; j < d.size(); ++j) {
    const double near = joint_margin(lower[j], upper[j], margin) + kLimitSlack;
    const bool low = at.joints()[j] - lower[j] <= near && d[j] < -noise;
    const bool high = upper[j] - at.joints()[j] <= near && d[j] > noise;
    if (!low && !high) continue;
    const double gap = low ? at.joints()[j] - lower[j] : upper[j] - at.joints()[j];
    out += (out.empty() ? "" : ", ") + names[j] + format(" %.1f° from its ", gap * 180 / M_PI) +
           (low ? "lower" : "upper") + " limit";
  }
  return out;
}

// The closest sphere pair, when it is within the margin and closes along d.
std::string collision(const ReducedObjective& objective, const Evaluation& at,
                      const Eigen::VectorXd& d) {
  const auto& collisions = objective.object().scene().robot->collisions;
  if (!collisions || collisions->pair_count() == 0 || d.norm() == 0) return {};
  const RobotModel& robot = objective.object().robot();
  const KinematicsState& here = at.state->kinematics();
  const double clearance = collisions->min_clearance(here);
  if (clearance > collisions->margin() + kClearanceSlack) return {};
  const Eigen::VectorXd probe = at.joints() + kCollisionProbe * d.normalized();
  if (collisions->min_clearance(forward_kinematics(robot, probe)) >= clearance) return {};
  const SphereClearance pair = collisions->closest_pairs(here, 1).front();
  const auto& spheres = collisions->spheres();
  return robot.links()[spheres[pair.first].link].name + "–" +
         robot.links()[spheres[pair.second].link].name +
         format(" clearance %.1f mm", pair.clearance * 1e3);
}

// How far a gripping arm is stretched: |tool − first joint| / the arm's length.
double stretch(const RobotModel& robot, const KinematicsState& state, const EndEffector& ee) {
  const Vec3 tool = state.T_world_link[ee.link] * ee.tcp_link;
  Vec3 previous = tool;
  double length = 0;
  Vec3 first = tool;
  for (int link = ee.link; robot.links()[link].parent_joint >= 0;) {
    const Joint& joint = robot.joints()[robot.links()[link].parent_joint];
    if (joint.movable()) {
      const Vec3 origin = state.T_world_link[joint.child_link].translation();
      length += (origin - previous).norm();
      previous = first = origin;
    }
    link = joint.parent_link;
  }
  return length > 0 ? (tool - first).norm() / length : 0;
}

std::string reach(const ReducedObjective& objective, const Evaluation& at) {
  const Scene& scene = objective.object().scene();
  std::set<int> gripping;
  for (const Grip& g : scene.grips) gripping.insert(g.end_effector);
  std::string out;
  for (int e : gripping) {
    const EndEffector& ee = scene.robot->end_effectors[e];
    const double s = stretch(objective.object().robot(), at.state->kinematics(), ee);
    if (s >= kStretched)
      out += (out.empty() ? "" : ", ") + ee.name + format(" arm stretched to %.0f %%", 100 * s);
  }
  return out;
}

// Whether a step along d loses the equilibrium or snaps to another one.
std::string buckling(const ReducedObjective& objective, Evaluation& at, const Eigen::VectorXd& d,
                     const StopRequest& stop) {
  if (d.norm() == 0) return {};
  const Eigen::VectorXd step = kBucklingProbe * d.normalized();
  Evaluation next = objective.evaluate(at.joints() + step, at.positions(), 0, &at, stop);
  if (!next.statics().converged() && stop && stop()) return {};  // out of time: not judged
  if (!objective.confirm_stable(next)) return "no stable equilibrium 0.02 rad further";
  const Eigen::VectorXd predicted = objective.sensitivity(at, false) * step;
  double moved = 0, expected = 0;
  for (int i : objective.targets().nodes) {
    moved = std::max(moved, (next.positions() - at.positions()).segment<3>(3 * i).norm());
    expected = std::max(expected, predicted.segment<3>(3 * i).norm());
  }
  if (moved > kSnapFactor * expected + kSnapFloor)
    return format("snaps %.1f mm where %.1f mm was predicted", moved * 1e3, expected * 1e3);
  return {};
}
}  // namespace

const char* to_string(Shortfall shortfall) { return kShortfalls.name(shortfall); }

bool parse(std::string_view name, Shortfall* shortfall) {
  return kShortfalls.parse(name, shortfall);
}

std::vector<std::string> shortfall_names(const std::vector<Shortfall>& shortfalls) {
  std::vector<std::string> names;
  for (Shortfall s : shortfalls) names.push_back(to_string(s));
  return names;
}

ShortfallReport find_shortfalls(const ReducedObjective& objective, Evaluation& at,
                                const StopRequest& stop) {
  ShortfallReport report;
  if (objective.targets().empty() || !at.statics().converged()) return report;
  const Eigen::VectorXd d = shape_descent(objective, at);
  const std::pair<Shortfall, std::string> found[] = {
      {Shortfall::Reach, reach(objective, at)},
      {Shortfall::JointLimit, joint_limit(objective, at, d)},
      {Shortfall::Collision, collision(objective, at, d)},
      {Shortfall::Buckling, buckling(objective, at, d, stop)}};
  std::string seen;  // what the end state shows, binding first
  for (const auto& [reason, words] : found) {
    if (words.empty()) continue;
    report.reasons.push_back(reason);
    seen += (seen.empty() ? "" : "; ") + std::string(to_string(reason)) + ": " + words;
  }
  const std::string beyond = beyond_unstretched_reach(objective.object(), objective.targets());
  if (!beyond.empty()) {
    report.reasons = {Shortfall::Reach};
    report.detail = "reach: " + beyond + (seen.empty() ? "" : "; where it stopped, " + seen);
  } else if (report.reasons.empty()) {
    report.detail = "no joint limit, collision, reach or buckling in the way: a local minimum";
  } else {
    report.detail = seen;
  }
  return report;
}

ShortfallReport find_run_shortfalls(const ReducedObjective& objective, Evaluation& best,
                                    Termination termination, const StopRequest& stop) {
  ShortfallReport report = find_shortfalls(objective, best, stop);
  const bool limited =
      termination == Termination::IterationLimit || termination == Termination::TimeLimit;
  if (limited && report.reasons.empty())
    report.detail = std::string("stopped by the ") + to_string(termination) +
                    " before the tolerance; no joint limit, collision, reach or buckling found "
                    "in the way";
  return report;
}

}  // namespace shapectl
