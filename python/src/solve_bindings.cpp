// shapectl.solve: what `shapectl solve` computes, from the reference joints to θ whose
// equilibrium best matches the targets, with the fields of its RESULT.json.
#include <cmath>
#include <limits>
#include <optional>

#include <shapectl/control/centerline.hpp>
#include <shapectl/control/controller.hpp>
#include <shapectl/control/optimize.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/kinematics.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

struct SolveResult {
  Eigen::VectorXd joints;
  std::vector<std::string> joint_names;
  bool converged = false;
  std::string termination;
  std::string reason;
  std::string status;  // reached, best effort, failed
  std::vector<std::string> unreachable;
  std::string status_reason;
  double tolerance = 0;
  int iterations = 0;
  double error_mean = 0, error_max = 0, objective = 0;
  std::optional<double> min_clearance;
  std::vector<LimitViolation> limit_violations;
  Vec3 loads_total = Vec3::Zero();
  std::optional<ContactsResult> contacts;
  Positions positions;
  ShapeTargets targets;
  std::vector<HistoryEntry> history;
  ObjectiveTiming timing;
  std::map<std::string, Pose> tools;
};

// Node targets as given, or the centre-line's (checked against this bar) as the CLI maps them.
ShapeTargets resolve(const TargetsInput& in, const std::string& source,
                     const GrippedObject& object) {
  if (in.centerline.empty()) {
    check_targets(in.targets, object.node_count(), source);
    return in.targets;
  }
  const auto axis = find_bar_axis(object.mesh());
  if (!axis)
    throw InputError(source, "centerline", "an object that is bar-like (length ≥ 3 × thickness)",
                     "a " + std::to_string(object.node_count()) + "-node object that is not");
  check_centerline(*axis, in.centerline, source);
  ShapeTargets targets =
      centerline_targets(object.mesh(), *axis, in.centerline, object.reference_positions());
  check_targets(targets, object.node_count(), source);
  return targets;
}

SolveResult solve(const SceneHandle& s, const py::object& targets_in,
                  const std::string& optimizer_name, const std::string& gradient_name,
                  Integer max_iterations, Real max_seconds, Real tolerance) {
  if (!s.scene->robot)
    throw InputError(s.scene->source.string(), "robot", "a robot to optimize (missing key)");
  const GrippedObject& object = *s.object;
  OptimizerKind kind;
  GradientMethod gradient;
  if (!parse(optimizer_name, &kind))
    throw InputError("optimizer", "", "one of the optimizer names", optimizer_name);
  if (!parse(gradient_name, &gradient))
    throw InputError("gradient", "", "one of the gradient names", gradient_name);
  if (max_iterations < 1) throw InputError("max_iterations", "", "a number >= 1", max_iterations);
  if (!(max_seconds > 0)) throw InputError("max_seconds", "", "a positive number", max_seconds);
  if (!(tolerance > 0)) throw InputError("tolerance", "", "a positive number of metres", tolerance);
  std::string source;
  const TargetsInput input = read_targets_from(targets_in, object.node_count(), source);

  py::gil_scoped_release release;
  const ReducedObjective objective(object, resolve(input, source, object), {}, s.workspaces);
  auto optimizer = make_optimizer(kind, gradient);
  const Evaluation start =
      objective.evaluate(object.reference_joints(), object.reference_positions());
  if (!start.statics().converged())
    throw SolverError("statics at the reference joints: " + start.statics().reason);
  OptimizeResult result = optimize(objective, *optimizer, start,
                                   {.max_iterations = max_iterations, .max_seconds = max_seconds});

  Evaluation& best = result.best;  // the shortfall probe may factor its state
  SolveResult out;
  out.joints = best.joints();
  out.joint_names = object.robot().active_joint_names();
  out.converged = result.converged();
  out.termination = to_string(result.termination);
  out.reason = result.reason;
  const ControllerStatus status =
      stopped_status(best, result.termination == Termination::Failed, tolerance);
  out.status = to_string(status);
  out.tolerance = tolerance;
  if (status == ControllerStatus::BestEffort) {
    const ShortfallReport shortfall = find_run_shortfalls(objective, best, result.termination);
    out.unreachable = shortfall_names(shortfall.reasons);
    out.status_reason = shortfall.detail;
  }
  out.iterations = result.iterations;
  out.error_mean = best.error.mean;
  out.error_max = best.error.max;
  out.objective = best.objective;
  // +inf without collision spheres: nothing to report.
  if (best.min_clearance != std::numeric_limits<double>::infinity())
    out.min_clearance = best.min_clearance;
  out.limit_violations = violations_at(object.robot(), best.joints());
  out.loads_total = s.scene->loads_total();
  out.positions = best.positions();
  const auto contact = object.contact_at(*best.state);
  out.contacts =
      contacts_at(contact ? &*contact : nullptr, object.statics().self_contact(), out.positions);
  out.targets = objective.targets();
  out.history = result.history;
  out.timing = objective.timing();
  out.tools = tool_poses(*s.scene, best.joints());
  if (!out.joints.allFinite() || !out.positions.allFinite() || !std::isfinite(out.objective))
    throw SolverError("solve: the result is not finite (" + result.reason + ")");
  return out;
}

py::array_t<int> target_nodes(const ShapeTargets& t) {
  return py::array_t<int>(t.nodes.size(), t.nodes.data());
}

py::array_t<double> target_positions(const ShapeTargets& t) {
  py::array_t<double> out({static_cast<py::ssize_t>(t.size()), py::ssize_t{3}});
  for (int k = 0; k < t.size(); ++k)
    for (int c = 0; c < 3; ++c) out.mutable_at(k, c) = t.positions[static_cast<std::size_t>(k)][c];
  return out;
}

}  // namespace

void bind_solve(py::module_& m) {
  py::class_<HistoryEntry>(m, "HistoryEntry", "One optimizer iteration (entry 0 is the start).")
      .def_readonly("iteration", &HistoryEntry::iteration, "Iteration number.")
      .def_readonly("time", &HistoryEntry::time, "Seconds since the start.")
      .def_readonly("error_mean", &HistoryEntry::error_mean,
                    "Mean distance of targeted nodes from their targets, m.")
      .def_readonly("objective", &HistoryEntry::objective, "Objective value.");

  py::class_<ObjectiveTiming>(m, "SolveTiming", "Where a solve spent its time.")
      .def_readonly("statics_solves", &ObjectiveTiming::statics_solves, "Statics solves.")
      .def_readonly("statics_seconds", &ObjectiveTiming::statics_seconds, "Seconds in statics.")
      .def_readonly("gradient_evaluations", &ObjectiveTiming::gradient_evaluations,
                    "Gradients or Jacobians.")
      .def_readonly("gradient_seconds", &ObjectiveTiming::gradient_seconds, "Seconds in them.");

  py::class_<SolveResult>(m, "SolveResult", "What `shapectl solve` writes to RESULT.json.")
      .def_readonly("joints", &SolveResult::joints, "The best θ found (rad): array of shape (m,).")
      .def_readonly("joint_names", &SolveResult::joint_names, "Names of θ's entries.")
      .def_readonly(
          "converged", &SolveResult::converged,
          "Stationary: no further progress possible (not necessarily the targets reached).")
      .def_readonly("termination", &SolveResult::termination,
                    "'converged', 'iteration limit', 'time limit', 'stuck' or 'failed'.")
      .def_readonly("reason", &SolveResult::reason, "The termination in words, with numbers.")
      .def_readonly("status", &SolveResult::status,
                    "'reached' (every target error within tolerance), 'best effort' (above it: "
                    "see unreachable) or 'failed'.")
      .def_readonly("unreachable", &SolveResult::unreachable,
                    "'best effort': why, of 'joint limit', 'collision', 'reach', 'buckling' "
                    "(empty: a local minimum).")
      .def_readonly("status_reason", &SolveResult::status_reason,
                    "'best effort' in words, with names and numbers; else empty.")
      .def_readonly("tolerance", &SolveResult::tolerance, "m, as given.")
      .def_readonly("iterations", &SolveResult::iterations, "Optimizer iterations.")
      .def_readonly("error_mean", &SolveResult::error_mean,
                    "Mean distance of targeted nodes from their targets, m.")
      .def_readonly("error_max", &SolveResult::error_max, "Largest such distance, m.")
      .def_readonly("objective", &SolveResult::objective, "Objective at the best θ.")
      .def_readonly("min_clearance", &SolveResult::min_clearance,
                    "Smallest sphere clearance, m; None without spheres.")
      .def_readonly("limit_violations", &SolveResult::limit_violations,
                    "Joints outside their hard limits.")
      .def_readonly("loads_total", &SolveResult::loads_total,
                    "Sum of the scene's applied loads, N, world frame: array of shape (3,).")
      .def_property_readonly(
          "contacts", [](const SolveResult& r) { return contacts_dict(r.contacts); },
          "Contacts with the scene's obstacles and with itself at the best θ, as "
          "StaticsSolution.contacts; None without obstacles and self-contact.")
      .def_property_readonly(
          "positions", [](const SolveResult& r) { return positions_array(r.positions); },
          "Equilibrium at the best θ: array of shape (n, 3).")
      .def_property_readonly(
          "target_nodes", [](const SolveResult& r) { return target_nodes(r.targets); },
          "Targeted nodes (a centre-line's resolved): int array of shape (k,).")
      .def_property_readonly(
          "target_positions", [](const SolveResult& r) { return target_positions(r.targets); },
          "Their targets, world frame, m: array of shape (k, 3).")
      .def_readonly("history", &SolveResult::history,
                    "One HistoryEntry per iteration, the start first.")
      .def_readonly("timing", &SolveResult::timing, "A SolveTiming.")
      .def_readonly("tools", &SolveResult::tools,
                    "Tool pose of each end effector at the best θ: {name: Pose}.");

  m.def(
      "solve", &solve, py::arg("scene"), py::arg("targets"), py::kw_only(),
      py::arg("optimizer") = "gauss-newton", py::arg("gradient") = "sensitivity",
      py::arg("max_iterations") = 100, py::arg("max_seconds") = 60.0, py::arg("tolerance") = 1e-3,
      "From the reference joints, θ whose equilibrium best matches `targets`, as `shapectl solve`. "
      "targets: a TARGETS.json path, or a dict of its schema ({'targets': [{'node': i, 'position': "
      "[x, y, z]}, …]} or {'centerline': [[x, y, z], …]}, numpy arrays allowed). optimizer: "
      "'gauss-newton' or 'lbfgs'; gradient (L-BFGS): 'sensitivity', 'adjoint' or "
      "'finite-difference'. "
      "Raises ValueError for bad input, SolverError when the reference statics fail. Releases the "
      "GIL while it runs, so other Python threads go on.");
}

}  // namespace shapectl::python
