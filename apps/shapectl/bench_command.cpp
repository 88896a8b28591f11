// shapectl bench [SCENE.json ...] [--trials N] [--seed S] [--scaling | --sizes 1.5k,6k,...]
//                [--json FILE]
// Reproduces the paper's performance figures (Section V-A) on the bundled scenes: time per
// reduced gradient by sensitivities, adjoint and finite differences, and the time and
// iterations from a target change to a mean error below 1 mm.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <numeric>
#include <optional>
#include <random>

#include <shapectl/calib/calibration.hpp>
#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/control/optimize.hpp>
#include <shapectl/control/optimizer.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/statics.hpp>

#include "bench_closed_loop.hpp"
#include "bench_json.hpp"
#include "bench_scaling.hpp"
#include "bench_targets.hpp"
#include "commands.hpp"
#include "linear_solver_option.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"

namespace shapectl::cli {

namespace {

using Clock = BenchClock;
constexpr auto seconds = seconds_between;

struct BenchArgs {
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::vector<std::string> scenes = {"scenes/yumi_bar.json", "scenes/yumi_frame.json"};
  int trials = 20;
  unsigned seed = 1;
  std::string sizes;  // --sizes / --scaling: the scaling table instead of the paper's
  bool no_krylov = false;
  bool double_chord = false;
  std::string json;  // --json: the figures also as JSON (bench_json.hpp)
  std::string linear_solver;
};

// Timings of one reduced-gradient variant, seconds.
struct GradientTimes {
  std::vector<double> sensitivity, sensitivity_factored, adjoint, adjoint_factored, fd_chord,
      fd_newton;
};

// 1. Reduced gradient, each method at the same states x̂(θ), each right after the statics
// solve that reached θ from the reference shape. "reused": the true Hessian at x̂ is already
// factored, as in an optimizer, which factors it to confirm an accepted state is stable
// (or as the last Newton step of a solve leaves it). "counted": that factorization is part
// of the timed gradient. "Newton": finite differences whose re-solves factor anew (no chord steps),
// the paper's baseline.
GradientTimes time_gradients(const GrippedObject& object, const ReducedObjective& objective,
                             const Evaluation& reference, int trials, std::mt19937& rng) {
  enum class Factor { Reused, Counted, NewtonResolves, ChordResolves };
  GradientTimes t;
  for (int trial = 0; trial < trials; ++trial) {
    ShapeTargets targets;
    if (!random_goal(objective, reference, rng, targets)) continue;
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    Eigen::VectorXd theta = reference.joints();
    for (int j = 0; j < theta.size(); ++j) theta[j] += u(rng);
    if (!objective.evaluate(theta, reference.positions()).statics().converged()) continue;
    for (auto [method, times, factor] :
         {std::tuple{GradientMethod::Sensitivity, &t.sensitivity, Factor::Reused},
          std::tuple{GradientMethod::Sensitivity, &t.sensitivity_factored, Factor::Counted},
          std::tuple{GradientMethod::Adjoint, &t.adjoint, Factor::Reused},
          std::tuple{GradientMethod::Adjoint, &t.adjoint_factored, Factor::Counted},
          std::tuple{GradientMethod::FiniteDifference, &t.fd_chord, Factor::ChordResolves},
          std::tuple{GradientMethod::FiniteDifference, &t.fd_newton, Factor::NewtonResolves}}) {
      const ReducedObjective variant(object, targets,
                                     {.stale_factor_step = factor == Factor::Counted ? 0.0 : 1e-6,
                                      .chord_steps = factor != Factor::NewtonResolves});
      Evaluation fresh = variant.evaluate(theta, reference.positions());
      if (factor == Factor::Reused && !variant.confirm_stable(fresh)) break;
      const auto t0 = Clock::now();
      variant.gradient(fresh, method);
      times->push_back(seconds(t0, Clock::now()));
    }
  }
  return t;
}

void print_gradient_times(const GradientTimes& t, nlohmann::json& record) {
  const double fd = percentile(t.fd_newton, 0.5);
  auto row = [&](const char* name, const std::vector<double>& times) {
    std::printf("    %-40s %8.3f ms   %6.1fx\n", name, 1e3 * percentile(times, 0.5),
                fd / percentile(times, 0.5));
  };
  std::printf(
      "  reduced gradient (median of %zu)                time      vs finite differences (Newton "
      "re-solves)\n",
      t.fd_newton.size());
  row("sensitivity, factorization at x reused", t.sensitivity);
  row("sensitivity, factorization counted", t.sensitivity_factored);
  row("adjoint, factorization at x reused", t.adjoint);
  row("adjoint, factorization counted", t.adjoint_factored);
  row("finite differences, chord re-solves", t.fd_chord);
  row("finite differences, Newton re-solves", t.fd_newton);
  record = {{"samples", t.fd_newton.size()}};
  for (auto [key, times] :
       {std::pair{"sensitivity", &t.sensitivity},
        std::pair{"sensitivity_factored", &t.sensitivity_factored},
        std::pair{"adjoint", &t.adjoint}, std::pair{"adjoint_factored", &t.adjoint_factored},
        std::pair{"fd_chord", &t.fd_chord}, std::pair{"fd_newton", &t.fd_newton}})
    record[key] = {{"median_s", percentile(*times, 0.5)}};
}

// Which random goals a target-change row draws (random_goal).
struct GoalDraw {
  double amplitude = 0.15;  // rad around the reference joints
  int min_contacts = 0;     // > 0: only goals resting on obstacles with this many contacts
  int attempts_per_trial = 1;
};

// 2. Target change → mean error below 1 mm, from the reference equilibrium.
void bench_target_changes(const ReducedObjective& objective, const Evaluation& reference,
                          OptimizerKind kind, const char* name, const BenchArgs& args,
                          nlohmann::json& record, const GoalDraw& draw = {}) {
  std::vector<double> times, iterations, newton, contacts;
  int failures = 0;
  std::mt19937 goals(args.seed + 1);
  const ObstacleContact* contact = objective.object().statics().contact();
  for (int attempt = 0, trial = 0;
       trial < args.trials && attempt < args.trials * draw.attempts_per_trial; ++attempt) {
    ShapeTargets targets;
    if (!random_goal(objective, reference, goals, targets, draw.amplitude, draw.min_contacts))
      continue;
    ++trial;
    const long long newton_before = statics_totals().iterations;
    Evaluation end;
    if (const auto reached =
            steps_to_1mm(objective.with_targets(targets), reference, kind, 10, &end)) {
      times.push_back(reached->first);
      iterations.push_back(reached->second);
    } else {
      ++failures;
    }
    newton.push_back(static_cast<double>(statics_totals().iterations - newton_before));
    if (contact) contacts.push_back(contact->summary(end.positions()).count);
  }
  std::printf(
      "  target change -> mean error < 1 mm, %-20s median %7.1f ms (p90 %7.1f, max %7.1f), "
      "iterations median %.0f (max %.0f), %d of %zu not reached; Newton iterations median %.0f",
      name, 1e3 * percentile(times, 0.5), 1e3 * percentile(times, 0.9),
      1e3 * percentile(times, 1.0), percentile(iterations, 0.5), percentile(iterations, 1.0),
      failures, times.size() + failures, percentile(newton, 0.5));
  if (contact)
    std::printf("; contacts at the end median %.0f (min %.0f)", percentile(contacts, 0.5),
                percentile(contacts, 0));
  std::printf("\n");
  record = {{"median_s", percentile(times, 0.5)},
            {"p90_s", percentile(times, 0.9)},
            {"max_s", percentile(times, 1.0)},
            {"iterations_median", percentile(iterations, 0.5)},
            {"iterations_max", percentile(iterations, 1.0)},
            {"newton_iterations_median", percentile(newton, 0.5)},
            {"reached", times.size()},
            {"trials", times.size() + failures}};
  if (contact) record["contacts_median"] = percentile(contacts, 0.5);
}

// Targets that push the first two grips' nodes 4 cm towards each other each.
ShapeTargets squeeze_targets(const Scene& scene, const Positions& x0) {
  ShapeTargets squeeze;
  Vec3 left = Vec3::Zero(), right = Vec3::Zero();
  for (int i : scene.grips[0].nodes) left += x0.segment<3>(3 * i) / scene.grips[0].nodes.size();
  for (int i : scene.grips[1].nodes) right += x0.segment<3>(3 * i) / scene.grips[1].nodes.size();
  const Vec3 inward = (right - left).normalized() * 0.04;
  for (int e = 0; e < 2; ++e)
    for (int i : scene.grips[e].nodes) {
      squeeze.nodes.push_back(i);
      squeeze.positions.push_back(x0.segment<3>(3 * i) + (e == 0 ? inward : Vec3(-inward)));
    }
  return squeeze;
}

// 3. The slow tail: push the gripped ends 4 cm towards each other each, so the object buckles.
void bench_buckling(const Scene& scene, const ReducedObjective& objective,
                    const Evaluation& reference, nlohmann::json& record) {
  if (scene.grips.size() < 2) {
    std::printf("  buckling: needs two grips to push together (this scene has %zu)\n",
                scene.grips.size());
    return;
  }
  const ReducedObjective buckle =
      objective.with_targets(squeeze_targets(scene, reference.positions()));
  Evaluation current = reference;
  buckle.rescore(current);
  GaussNewton optimizer;
  const auto t0 = Clock::now();
  const OptimizeResult r =
      optimize(buckle, optimizer, current, {.max_iterations = 100, .max_seconds = 20});
  double to_1mm = NAN;
  for (const auto& h : r.history)
    if (h.error_mean < 1e-3) {
      to_1mm = h.time;
      break;
    }
  std::printf(
      "  buckling (grips pushed 2 x 4 cm together), gauss-newton: %s after %d iterations, %.0f ms; "
      "< 1 mm after %.0f ms; final mean error %.3f mm\n",
      to_string(r.termination), r.iterations, 1e3 * seconds(t0, Clock::now()), 1e3 * to_1mm,
      1e3 * r.best.error.mean);
  record = {{"termination", to_string(r.termination)},
            {"iterations", r.iterations},
            {"seconds", seconds(t0, Clock::now())},
            {"to_1mm_s", to_1mm},
            {"error_mean", r.best.error.mean}};
}

// Calibration (docs/calibration.md) on synthetic observations: the "real" object 1.8× stiffer
// and held 4 mm / 3° off at each grip, 15 markers with 0.3 mm noise at 3 poses; fit Young's
// modulus and the grip offsets. Median wall time over noise seeds.
void bench_calibration(const Scene& scene, const BenchArgs& args, nlohmann::json& record) {
  Scene truth = scene;
  truth.material = material_from_youngs(1.8 * youngs_modulus_of(scene.material),
                                        poisson_ratio_of(scene.material), scene.material.density);
  for (Grip& g : truth.grips)
    g.offset = Eigen::Translation3d(0.004 * Vec3(1, 1, -1).normalized()) *
               Eigen::AngleAxisd(3 * M_PI / 180, Vec3::UnitZ());
  const GrippedObject world(truth);
  std::vector<Eigen::VectorXd> poses(3, scene.robot->reference_joints);
  // The first arm's shoulder, elbow and wrist: turning the object against gravity is what
  // separates its sag (stiffness) from a tilt in the gripper (grip rotation).
  if (poses[0].size() >= 7)
    poses[1][0] += 0.15, poses[1][6] += 0.5, poses[2][3] -= 0.2, poses[2][5] += 0.3;
  std::vector<Positions> shapes;
  for (const auto& joints : poses)
    shapes.push_back(equilibrium_along_path(world, joints).positions());
  SimulatedCamera camera;
  std::vector<int> nodes(world.node_count());
  std::iota(nodes.begin(), nodes.end(), 0);
  std::shuffle(nodes.begin(), nodes.end(), std::mt19937(7));  // 15 markers anywhere on the object
  camera.marker_nodes.assign(nodes.begin(), nodes.begin() + 15);
  std::vector<double> times, stiffness_errors, stiffness_deviations;
  std::string held;
  const int trials = std::min(args.trials, 5);
  for (int trial = 0; trial < trials; ++trial) {
    std::mt19937 rng(args.seed + trial);
    Observations observations;
    for (std::size_t f = 0; f < poses.size(); ++f)
      observations.frames.push_back(camera.observe(world.mesh(), shapes[f], poses[f], rng));
    const CalibrationResult r =
        calibrate(scene, observations, parse_fit_selection("youngs_modulus,grip_offsets"));
    times.push_back(r.seconds);
    stiffness_errors.push_back(
        std::abs(r.fitted.youngs_modulus / youngs_modulus_of(truth.material) - 1));
    stiffness_deviations.push_back(r.parameters[0].standard_deviation / r.fitted.youngs_modulus);
    held.clear();
    for (const FittedParameter& p : r.parameters)
      if (p.verdict != Verdict::Determined)
        held += " " + p.name + " (" + to_string(p.verdict) + ")";
  }
  std::printf(
      "  calibration, 3 frames x 15 markers, E + grip offsets (%d noise seeds): median %.3f s, "
      "max %.3f s; E off by %.1f %% (median; reported standard deviation %.1f %%)%s\n",
      trials, percentile(times, 0.5), percentile(times, 1), 100 * percentile(stiffness_errors, 0.5),
      100 * percentile(stiffness_deviations, 0.5),
      held.empty() ? "" : ("; not all determined:" + held).c_str());
  record = {{"median_s", percentile(times, 0.5)},
            {"max_s", percentile(times, 1)},
            {"trials", trials},
            {"youngs_error", percentile(stiffness_errors, 0.5)},
            {"held", held}};
}

void bench_scene(const std::string& file, const BenchArgs& args, nlohmann::json& record) {
  Scene scene = load_scene(file);
  apply_linear_solver_option(args.linear_solver, scene);
  print_scene_notes(scene, args.package_paths);
  if (!scene.robot) throw InputError(file, "robot", "a scene with a robot (missing key)");
  GrippedObject object(scene);
  ReducedObjective objective(object);
  std::mt19937 rng(args.seed);
  const Evaluation reference =
      objective.evaluate(object.reference_joints(), object.reference_positions());
  if (!reference.statics().converged())
    throw SolverFailure("statics at the reference: " + reference.statics().reason);
  std::printf("\n%s: %d tets, %d nodes, %d joints\n", file.c_str(), object.mesh().tet_count(),
              object.node_count(), object.joint_count());
  record["tets"] = object.mesh().tet_count();
  print_gradient_times(time_gradients(object, objective, reference, args.trials, rng),
                       record["gradient"]);
  for (auto [kind, name, key] :
       {std::tuple{OptimizerKind::GaussNewton, "gauss-newton", "gauss_newton"},
        std::tuple{OptimizerKind::Lbfgs, "lbfgs (sensitivity)", "lbfgs"}})
    bench_target_changes(objective, reference, kind, name, args, record[key]);
  // Shapes resting on an obstacle (issue 34: the cable on the table, >= 100 contacts): smaller
  // joint moves, and only goals whose equilibrium keeps that many contacts.
  if (object.statics().contact())
    bench_target_changes(objective, reference, OptimizerKind::GaussNewton, "g-n, >=100 contacts",
                         args, record["gauss_newton_resting"],
                         {.amplitude = 0.05, .min_contacts = 100, .attempts_per_trial = 10});
  bench_buckling(scene, objective, reference, record["buckling"]);
  bench_calibration(scene, args, record["calibration"]);
  bench_closed_loop(scene, std::min(args.trials, 3), args.seed, record["closed_loop"]);
}

}  // namespace

// The scaling table's sizes by default; 50k (≈ 2 min more) only when asked for.
constexpr const char* kDefaultSizes = "1.5k,6k,12k,25k";

void add_bench_command(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  auto* cmd =
      app.add_subcommand("bench", "Reproduce the paper's performance table on the bundled scenes");
  auto* scenes =
      cmd->add_option("scenes", args->scenes,
                      "scene files (default: scenes/yumi_bar.json scenes/yumi_frame.json; with "
                      "--sizes the first only, default scenes/yumi_bar.json)");
  cmd->add_option("--trials", args->trials, "random target sets per measurement")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--seed", args->seed, "random seed");
  add_linear_solver_option(*cmd, args->linear_solver);
  add_package_path_option(*cmd, args->package_paths);
  cmd->add_option("--sizes", args->sizes,
                  "instead: the scaling table, the scene's box mesh refined to about these tet "
                  "counts (e.g. 1.5k,6k,12k,25k,50k)");
  cmd->add_flag("--no-krylov", args->no_krylov,
                "with --sizes: statics without conjugate-gradient steps (to measure them)");
  cmd->add_flag("--double-chord", args->double_chord,
                "with --sizes: chord and Krylov steps solve in double precision, not single (to "
                "measure what single saves)");
  cmd->add_option("--json", args->json,
                  "also write the figures to this JSON file (for scripts/bench_table.py)")
      ->check(writable_output());
  cmd->add_flag_callback(
      "--scaling", [args] { args->sizes = kDefaultSizes; },
      std::string("the scaling table at ") + kDefaultSizes + " tets (--sizes " + kDefaultSizes +
          ")");
  cmd->callback([args, scenes] {
    check_linear_solver_option("bench", args->linear_solver);
    nlohmann::json record = nlohmann::json::object();
    if (!args->sizes.empty()) {
      const auto counts = parse_tet_counts(args->sizes, "--sizes");
      bench_scaling(scenes->count() ? args->scenes.front() : "scenes/yumi_bar.json", counts,
                    args->trials, args->seed,
                    {.krylov_steps = !args->no_krylov,
                     .single_precision_chord = !args->double_chord,
                     .linear_solver = args->linear_solver},
                    record["sizes"]);
      write_bench_record(args->json, record);
      return;
    }
    for (const auto& s : args->scenes) bench_scene(s, *args, record["scenes"][s]);
    write_bench_record(args->json, record);
  });
}

}  // namespace shapectl::cli
