// shapectl calibrate SCENE.json --observations OBS.json --out CALIBRATED.json
//   [--fit youngs_modulus,poisson_ratio,density,grip_offsets,object_pose,camera_poses,
//          regions[K].youngs_modulus]
//   [--report REPORT.json]
//   [--prior LIST] [--bounds LIST] [--max-iterations N] [--max-seconds S]
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
  std::string fit;            // default: default_fit(scene)
  std::string prior, bounds;  // parse_priors, parse_bounds
  std::string linear_solver;
  int max_iterations = 30;
  double max_seconds = 300;  // the whole command
};

// The parameters to fit; --fit names one the scene does not have → InputError naming --fit.
// The depth cameras camera_poses needs are the observations': checked_against_cameras.
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
    FitSelection of_the_scene = fit;
    of_the_scene.camera_poses = false;
    const ParameterSpace space(scene, of_the_scene);  // refuses what the scene does not have
  } catch (const std::invalid_argument& e) {
    throw InputError("--fit", "", std::string(e.what()) + " (" + args.scene + ")");
  }
  return fit;
}

// camera_poses without a depth image in the observations → InputError naming --fit.
void checked_against_cameras(const CalibrateArgs& args, const Scene& scene, const FitSelection& fit,
                             const Observations& observations) {
  try {
    const ParameterSpace space(scene, fit, camera_count(observations));
  } catch (const std::invalid_argument& e) {
    throw InputError("--fit", "", std::string(e.what()) + " (" + args.observations + ")");
  }
}

// --prior and --bounds over the observations file's "priors" and "bounds" (the command line's
// entries win); a bad entry → InputError naming the option and the entry. The scene's material
// must lie within the bounds.
void priors_and_bounds(const CalibrateArgs& args, const Scene& scene, const FitSelection& fit,
                       const Observations& observations, CalibrationOptions& options) {
  try {
    options.priors = parse_priors(args.prior, observations.priors.value_or(CalibrationPriors{}));
  } catch (const std::invalid_argument& e) {
    throw InputError("--prior", "", e.what());
  }
  try {
    options.bounds = parse_bounds(args.bounds, observations.bounds.value_or(MaterialBounds{}));
  } catch (const std::invalid_argument& e) {
    throw InputError("--bounds", "", e.what());
  }
  const std::string name = outside_bounds(ParameterSpace(scene, fit, camera_count(observations)),
                                          PhysicalParameters::of(scene), options.bounds);
  if (name.empty()) return;
  const std::string problem =
      name + ": the scene's value (" + args.scene + ") is outside these bounds";
  // Bounds the file alone gave are named where they were written.
  if (args.bounds.empty()) throw InputError(args.observations, "bounds", problem);
  throw InputError("--bounds", "", problem);
}

// A value's prior σ, or null without one.
nlohmann::ordered_json or_null(double value, bool present) {
  return present ? nlohmann::ordered_json(value) : nlohmann::ordered_json();
}

nlohmann::ordered_json report_json(const CalibrationResult& r) {
  nlohmann::ordered_json out;
  out["converged"] = r.converged;
  out["reason"] = r.reason;
  out["iterations"] = r.iterations;
  out["seconds"] = r.seconds;
  out["parameters"] = nlohmann::ordered_json::array();
  for (const FittedParameter& p : r.parameters)
    out["parameters"].push_back({{"name", p.name},
                                 {"unit", p.unit},
                                 {"initial", p.initial},
                                 {"fitted", p.fitted},
                                 {"standard_deviation", or_null(p.standard_deviation, !p.held)},
                                 {"identifiable", !p.held},
                                 {"verdict", to_string(p.verdict)},
                                 {"prior", or_null(p.prior, p.prior > 0)},
                                 {"implausible", p.implausible},
                                 {"trades_off_with", p.trades_off_with},
                                 {"suggestion", p.suggestion}});
  out["implausible"] = r.implausible;
  out["identifiability"] = nlohmann::ordered_json::array();
  for (const UnidentifiedDirection& d : r.unidentified) {
    nlohmann::ordered_json combination;
    for (const auto& [name, weight] : d.combination) combination[name] = weight;
    out["identifiability"].push_back({{"not_determined", combination},
                                      {"standard_deviation_in_scales", d.standard_deviation},
                                      {"held_at_initial_value", d.held},
                                      {"suggestion", d.suggestion}});
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
    std::cerr << "calibrate: not determined by these observations:";
    for (const auto& [name, weight] : d.combination)
      std::cerr << " " << name << " (" << weight << ")";
    std::cerr << " together; " << d.held
              << " held at its initial value; would determine it: " << d.suggestion << "\n";
  }
  for (const FittedParameter& p : r.parameters) {
    std::cerr << "  " << p.name << ": " << p.initial << " -> " << p.fitted;
    if (!p.held) std::cerr << " ± " << p.standard_deviation;
    std::cerr << " " << p.unit << " (" << to_string(p.verdict);
    if (p.prior > 0) std::cerr << "; prior σ " << p.prior << " " << p.unit;
    std::cerr << ")\n";
  }
  for (const FittedParameter& p : r.parameters)
    if (p.implausible)
      std::cerr << "calibrate: warning: " << p.name << " moved " << p.fitted - p.initial << " "
                << p.unit << ", more than 3 prior σ (" << p.prior << " " << p.unit
                << "): implausible; the model may miss something the fit absorbs here\n";
  // Background the fit reads and drops every iteration: worth cutting away before the fit.
  for (std::size_t k = 0; k < r.frames.size(); ++k)
    if (const FrameFit& f = r.frames[k]; f.points > 0 && 2 * f.inlier_points_after < f.points)
      std::cerr << "calibrate: note: frames[" << k << "]: only " << f.inlier_points_after << " of "
                << f.points << " points lie near the fitted surface; the rest (the table, the "
                << "robot, the room?) were read as outliers on every iteration: a \"crop\" box "
                << "(depth images) or a cropped cloud would leave them out\n";
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
                         .robot = scene.robot ? scene.robot->model.get() : nullptr,
                         .mesh = scene.object_mesh.get()});
  checked_against_cameras(args, scene, fit, observations);
  CalibrationOptions options{.max_iterations = args.max_iterations};
  priors_and_bounds(args, scene, fit, observations, options);
  CalibrationResult result;
  try {
    options.max_seconds = remaining();
    result = calibrate(scene, observations, fit, options);
  } catch (const std::invalid_argument& e) {  // a selection these observations refuse
    throw InputError("--fit", "", std::string(e.what()) + " (" + args.observations + ")");
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
      "object_pose, camera_poses (the depth images' cameras), regions[K].youngs_modulus (also "
      ".poisson_ratio, .density: region K's material) (default youngs_modulus,grip_offsets with a "
      "robot, "
      "youngs_modulus,object_pose for an object held by fixed nodes alone)");
  cmd->add_option("--prior", args->prior,
                  "priors on the fitted values' change from the scene's, comma-separated "
                  "NAME=SIGMA: object_pose.translation=10mm, object_pose.rotation=2deg, "
                  "grip_offsets=5mm/3deg, camera_poses=10mm/2deg, youngs_modulus=50% (mm, m, deg, "
                  "rad; % for material); none disables one, off alone all (defaults: object_pose "
                  "and camera_poses 10mm/2deg, grip_offsets 5mm/3deg, none on material)");
  cmd->add_option("--bounds", args->bounds,
                  "hard bounds on the material, comma-separated NAME=LOWER:UPPER (a side may be "
                  "empty): youngs_modulus=1e3:1e8, density=100:2000, poisson_ratio=0.2:0.49");
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
