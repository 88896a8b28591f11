// shapectl calibrate SCENE.json --observations OBS.json --out CALIBRATED.json
//   [--fit youngs_modulus,poisson_ratio,density,grip_offsets,object_pose] [--report REPORT.json]
//   [--max-iterations N] [--max-seconds S]
// Fits the scene's physical parameters to observed frames of the real object
// (docs/calibration.md) and writes the scene with the fitted values.
#include <algorithm>
#include <chrono>
#include <iostream>

#include <shapectl/calib/calibration.hpp>
#include <shapectl/io/atomic_file.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/scene_io/scene_writer.hpp>

#include "commands.hpp"
#include "linear_solver_option.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"

namespace shapectl::cli {

namespace {

struct CalibrateArgs {
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::string scene, observations, out, report;
  std::string fit;  // default: default_fit(scene)
  std::string linear_solver;
  int max_iterations = 30;
  double max_seconds = 300;  // the whole command
};

// The parameters to fit; --fit names one the scene does not have → InputError naming --fit.
FitSelection fit_selection(const CalibrateArgs& args, const Scene& scene) {
  const std::string list = args.fit.empty() ? default_fit(scene) : args.fit;
  FitSelection fit;
  try {
    fit = parse_fit_selection(list);
  } catch (const std::invalid_argument&) {
    throw InputError("--fit", "", std::string("a comma-separated list of ") + fit_parameter_names(),
                     list);
  }
  try {
    const ParameterSpace space(scene, fit);  // refuses what the scene does not have
  } catch (const std::invalid_argument& e) {
    throw InputError("--fit", "", std::string(e.what()) + " (" + args.scene + ")");
  }
  return fit;
}

nlohmann::ordered_json report_json(const CalibrationResult& r) {
  nlohmann::ordered_json out;
  out["converged"] = r.converged;
  out["reason"] = r.reason;
  out["iterations"] = r.iterations;
  out["seconds"] = r.seconds;
  out["parameters"] = nlohmann::ordered_json::array();
  for (const FittedParameter& p : r.parameters)
    out["parameters"].push_back(
        {{"name", p.name},
         {"unit", p.unit},
         {"initial", p.initial},
         {"fitted", p.fitted},
         {"standard_deviation",
          p.held ? nlohmann::ordered_json() : nlohmann::ordered_json(p.standard_deviation)},
         {"identifiable", !p.held}});
  out["identifiability"] = nlohmann::ordered_json::array();
  for (const UnidentifiedDirection& d : r.unidentified) {
    nlohmann::ordered_json combination;
    for (const auto& [name, weight] : d.combination) combination[name] = weight;
    out["identifiability"].push_back({{"not_determined", combination},
                                      {"standard_deviation_in_scales", d.standard_deviation},
                                      {"held_at_initial_value", d.held}});
  }
  out["rms_before"] = r.rms_before;
  out["rms_after"] = r.rms_after;
  out["chi_squared_per_dof"] = r.chi_squared_per_dof;
  out["frames"] = nlohmann::ordered_json::array();
  for (const FrameFit& f : r.frames)
    out["frames"].push_back({{"rms_before", f.rms_before},
                             {"rms_after", f.rms_after},
                             {"markers", f.markers},
                             {"points", f.points},
                             {"inlier_points_after", f.inlier_points_after}});
  return out;
}

void print_summary(const CalibrationResult& r) {
  for (const UnidentifiedDirection& d : r.unidentified) {
    std::cerr << "calibrate: not identifiable from these observations:";
    for (const auto& [name, weight] : d.combination)
      std::cerr << " " << name << " (" << weight << ")";
    std::cerr << " together; " << d.held << " held at its initial value\n";
  }
  for (const FittedParameter& p : r.parameters) {
    std::cerr << "  " << p.name << ": " << p.initial << " -> " << p.fitted;
    if (p.held) std::cerr << " (held)";
    else std::cerr << " ± " << p.standard_deviation;
    std::cerr << " " << p.unit << "\n";
  }
  std::cerr << "calibrate: " << r.reason << "; RMS residual " << r.rms_before * 1e3 << " mm -> "
            << r.rms_after * 1e3 << " mm (χ²/dof " << r.chi_squared_per_dof << ") in " << r.seconds
            << " s\n";
}

void run_calibrate(const CalibrateArgs& args) {
  // --max-seconds bounds the whole command; the fit checks it between pieces that cannot be
  // cut (a Newton iteration, a factorization, a sensitivity solve), so it aims at 90 %.
  const auto started = std::chrono::steady_clock::now();
  const auto remaining = [&] {
    const std::chrono::duration<double> spent = std::chrono::steady_clock::now() - started;
    return std::max(0.0, 0.9 * args.max_seconds - spent.count());
  };
  if (!(args.max_seconds > 0))
    throw InputError("calibrate", "--max-seconds", "a positive number of seconds",
                     args.max_seconds);
  check_linear_solver_option("calibrate", args.linear_solver);
  Scene scene = load_scene(args.scene);
  apply_linear_solver_option(args.linear_solver, scene);
  print_scene_notes(scene, args.package_paths);
  const FitSelection fit = fit_selection(args, scene);
  const Observations observations =
      load_observations(args.observations,
                        {.node_count = scene.object_mesh->node_count(),
                         .robot = scene.robot ? scene.robot->model.get() : nullptr});
  CalibrationResult result;
  try {
    result = calibrate(scene, observations, fit,
                       {.max_iterations = args.max_iterations, .max_seconds = remaining()});
  } catch (const std::runtime_error& e) {
    throw SolverFailure(std::string("calibrate: ") + e.what() +
                        (remaining() > 0 ? "" : " (--max-seconds reached)"));
  }
  const nlohmann::ordered_json report = report_json(result);
  require_finite(report, "calibrate", result.reason);
  std::vector<FileContent> files = {
      {args.out, to_pretty_json(scene_json_with_values(args.scene, result.scene, args.out))}};
  if (!args.report.empty()) files.push_back({args.report, to_pretty_json(report)});
  write_files_atomically(files);
  print_summary(result);
  if (!result.converged)
    throw SolverFailure("calibrate: not converged (" + result.reason +
                        (remaining() > 0 ? "" : ", --max-seconds reached") +
                        "); the best values so far are written");
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Fit material, grip offsets or the object's pose to observations of the real object");
  cmd->add_option("scene", args->scene, "SCENE.json")->required();
  cmd->add_option("--observations", args->observations, "OBSERVATIONS.json (docs/calibration.md)")
      ->required();
  cmd->add_option("--out", args->out, "CALIBRATED.json: the scene with the fitted values")
      ->required()
      ->check(writable_output());
  cmd->add_option(
      "--fit", args->fit,
      "parameters to fit, comma-separated: youngs_modulus, poisson_ratio, density, grip_offsets, "
      "object_pose (default youngs_modulus,grip_offsets with a robot, "
      "youngs_modulus,object_pose for an object held by fixed nodes alone)");
  cmd->add_option("--report", args->report,
                  "REPORT.json: values, standard deviations, residuals, identifiability")
      ->check(writable_output());
  cmd->add_option("--max-iterations", args->max_iterations, "iteration limit")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--max-seconds", args->max_seconds,
                  "time limit of the whole command: the fit stops with the best values so far")
      ->capture_default_str();
  add_linear_solver_option(*cmd, args->linear_solver);
  add_package_path_option(*cmd, args->package_paths);
  cmd->callback([args] { run_calibrate(*args); });
}

}  // namespace shapectl::cli
