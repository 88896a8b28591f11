// shapectl solve SCENE.json --targets TARGETS.json --out RESULT.json [--vtu DEFORMED.vtu]
//   [--surface SURFACE.ply|SURFACE.obj]
//   [--optimizer lbfgs|gauss-newton] [--gradient sensitivity|adjoint|finite-difference]
//   [--max-iterations N] [--max-seconds S] [--tolerance M]
// Finds joint angles whose equilibrium shape best matches the targets.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <limits>

#include <shapectl/control/centerline.hpp>
#include <shapectl/control/controller.hpp>
#include <shapectl/control/optimize.hpp>
#include <shapectl/control/reach_bound.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/atomic_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/io/vtu_writer.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"
#include "linear_solver_option.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"
#include "surface_option.hpp"

namespace shapectl::cli {

namespace {

struct SolveArgs {
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::string scene, targets, out, vtu, surface;
  std::string linear_solver;
  std::string optimizer = "gauss-newton";
  std::string gradient = "sensitivity";
  int max_iterations = 100;
  double max_seconds = 60;
  double tolerance = 1e-3;  // m
};

// The targets the file asks for, checked against this object (InputError naming the file).
ShapeTargets resolve_targets(const TargetsInput& in, const std::string& file,
                             GrippedObject& object) {
  if (in.centerline.empty()) {
    check_targets(in.targets, object.node_count(), file);
    return in.targets;
  }
  const auto axis = find_bar_axis(object.mesh());
  if (!axis)
    throw InputError(file, "centerline", "an object that is bar-like (length ≥ 3 × thickness)",
                     "a " + std::to_string(object.mesh().node_count()) +
                         "-node object that is not");
  check_centerline(*axis, in.centerline, file);
  ShapeTargets targets =
      centerline_targets(object.mesh(), *axis, in.centerline, object.reference_positions());
  check_targets(targets, object.node_count(),
                file);  // the bar's offsets may still reach past the bound
  return targets;
}

void run_solve(const SolveArgs& args) {
  // --max-seconds bounds the whole command: the statics at the start, each trial's statics and
  // the buckling probe stop at it too, not only the optimizer's steps. Checks come between
  // pieces that cannot be cut (a Newton iteration, a factorization, a sensitivity solve: up to
  // ~0.5 s each at 50k tets), so they aim at 90 % of the budget.
  const auto started = std::chrono::steady_clock::now();
  const auto elapsed = [started] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  const double aim = 0.9 * args.max_seconds;
  const StopRequest out_of_time = [&] { return elapsed() > aim; };
  check_surface_option("solve", args.surface);
  check_linear_solver_option("solve", args.linear_solver);
  Scene scene = load_scene(args.scene);
  apply_linear_solver_option(args.linear_solver, scene);
  print_scene_notes(scene, args.package_paths);
  if (!scene.robot) throw InputError(args.scene, "robot", "a robot to optimize (missing key)");
  GrippedObject object(scene);
  const TargetsInput input = load_targets(args.targets, object.node_count());
  check_in_reach(object, input, args.targets);  // a file in mm read as metres: refused now
  const ReducedObjective objective(object, resolve_targets(input, args.targets, object));

  OptimizerKind kind;
  GradientMethod gradient;
  if (!parse(args.optimizer, &kind))
    throw InputError("--optimizer", "", "one of the optimizer names", args.optimizer);
  if (!parse(args.gradient, &gradient))
    throw InputError("--gradient", "", "one of the gradient names", args.gradient);
  auto optimizer = make_optimizer(kind, gradient);
  const Evaluation start =
      objective.evaluate(object.reference_joints(), object.reference_positions(), 0, nullptr,
                         out_of_time);
  if (!start.statics().converged())
    throw SolverFailure("statics at the reference joints: " + start.statics().reason +
                        (out_of_time() ? " (--max-seconds reached)" : ""));
  OptimizeResult result = optimize(objective, *optimizer, start,
                                   {.max_iterations = args.max_iterations,
                                    .max_seconds = std::max(0.0, aim - elapsed())});

  Evaluation& best = result.best;  // the shortfall probe may factor its state
  nlohmann::json out = robot_json(scene, best.joints());
  out["converged"] = result.converged();
  out["termination"] = to_string(result.termination);
  out["reason"] = result.reason;
  // The run's verdict in the controller's words: reached, best effort (with why) or failed.
  const ControllerStatus status =
      stopped_status(best, result.termination == Termination::Failed, args.tolerance);
  out["status"] = to_string(status);
  out["tolerance"] = args.tolerance;
  ShortfallReport shortfall;
  if (status == ControllerStatus::BestEffort)
    shortfall = find_run_shortfalls(objective, best, result.termination, out_of_time);
  out["unreachable"] = shortfall_names(shortfall.reasons);
  out["status_reason"] = shortfall.detail;
  out["iterations"] = result.iterations;
  out["error_mean"] = best.error.mean;
  out["error_max"] = best.error.max;
  out["objective"] = best.objective;
  // +inf without collision spheres: nothing to report (JSON has no infinity).
  if (best.min_clearance != std::numeric_limits<double>::infinity())
    out["min_clearance"] = best.min_clearance;
  nlohmann::json violations = nlohmann::json::array();
  const KinematicsState state = forward_kinematics(object.robot(), best.joints());
  for (const auto& v : limit_violations(object.robot(), state.joints))
    violations.push_back(
        {{"joint", v.joint}, {"value", v.value}, {"lower", v.lower}, {"upper", v.upper}});
  out["limit_violations"] = violations;
  out["loads_total"] = vec3_json(scene.loads_total());
  const auto contact = object.contact_at(*best.state);
  if (auto contacts = contacts_json(contact ? &*contact : nullptr, object.statics().self_contact(),
                                    best.positions());
      !contacts.is_null())
    out["contacts"] = std::move(contacts);
  out["positions"] = positions_json(best.positions());
  out["targets"] = targets_json(objective.targets());
  for (const auto& h : result.history)
    out["history"].push_back({{"iteration", h.iteration},
                              {"time", h.time},
                              {"error_mean", h.error_mean},
                              {"objective", h.objective}});
  const ObjectiveTiming t = objective.timing();
  out["timing"] = {{"statics_solves", t.statics_solves},
                   {"statics_seconds", t.statics_seconds},
                   {"gradient_evaluations", t.gradient_evaluations},
                   {"gradient_seconds", t.gradient_seconds}};
  require_finite(out, "solve", result.reason);
  // With --vtu or --surface all files or none.
  std::vector<FileContent> files = {{args.out, to_pretty_json(out)}};
  if (!args.vtu.empty()) {
    std::vector<std::array<int, 4>> tets;
    for (const auto& t : object.mesh().tets()) tets.push_back(t.nodes);
    const Positions rest = scene.world_rest_positions();
    files.push_back(
        {args.vtu, vtu_text(best.positions(), tets, {{"displacement", best.positions() - rest}})});
  }
  if (!args.surface.empty())
    files.push_back(surface_file(args.surface, object.mesh(), best.positions()));
  write_files_atomically(files);
  std::cerr << "solve: " << to_string(status)
            << (shortfall.detail.empty() ? "" : " (" + shortfall.detail + ")") << "; "
            << result.reason << "; mean error " << best.error.mean * 1e3 << " mm, max "
            << best.error.max * 1e3 << " mm, min clearance " << best.min_clearance * 1e3 << " mm\n";
}

}  // namespace

void add_solve_command(CLI::App& app) {
  auto args = std::make_shared<SolveArgs>();
  auto* cmd =
      app.add_subcommand("solve", "Find joint angles that give the object the target shape");
  cmd->add_option("scene", args->scene, "SCENE.json")->required();
  cmd->add_option("--targets", args->targets, "TARGETS.json")->required();
  cmd->add_option("--out", args->out, "RESULT.json to write")->required()->check(writable_output());
  cmd->add_option("--vtu", args->vtu,
                  "also write the deformed mesh at the best joints as VTU (ParaView)")
      ->check(writable_output());
  add_surface_option(*cmd, args->surface);
  add_linear_solver_option(*cmd, args->linear_solver);
  cmd->add_option("--optimizer", args->optimizer, "gauss-newton (default) or lbfgs")
      ->check(CLI::IsMember(optimizer_names()));
  cmd->add_option("--gradient", args->gradient,
                  "sensitivity (default), adjoint or finite-difference")
      ->check(CLI::IsMember(gradient_names()));
  cmd->add_option("--max-iterations", args->max_iterations, "iteration limit")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--max-seconds", args->max_seconds, "time limit")->check(CLI::PositiveNumber);
  add_package_path_option(*cmd, args->package_paths);
  add_tolerance_option(*cmd, args->tolerance);
  cmd->callback([args] { run_solve(*args); });
}

}  // namespace shapectl::cli
