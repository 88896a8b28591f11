#include "bench_scaling.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "bench_targets.hpp"
#include "linear_solver_option.hpp"

namespace shapectl::cli {

namespace {

// Cells of a structured box mesh along each axis (distinct node coordinates − 1), or none if
// the mesh is not a full box (6 tets per cell, no hole).
std::optional<std::array<int, 3>> box_cells(const TetMesh& mesh) {
  std::array<std::set<double>, 3> coordinates;
  for (const Vec3& p : mesh.rest_positions())
    for (int k = 0; k < 3; ++k) coordinates[k].insert(p[k]);
  std::array<int, 3> cells{};
  for (int k = 0; k < 3; ++k) cells[k] = static_cast<int>(coordinates[k].size()) - 1;
  if (6LL * cells[0] * cells[1] * cells[2] != mesh.tet_count()) return std::nullopt;
  return cells;
}

// The scene with its box refined to about `tets` tetrahedra (every axis by the same factor);
// each grip holds the nodes inside the box its original nodes spanned.
Scene refined_scene(const Scene& scene, const std::array<int, 3>& base_cells, int tets) {
  const TetMesh& base = *scene.object_mesh;
  const double factor = std::cbrt(tets / (6.0 * base_cells[0] * base_cells[1] * base_cells[2]));
  std::array<int, 3> cells{};
  for (int k = 0; k < 3; ++k)
    cells[k] = std::max(1, static_cast<int>(std::lround(base_cells[k] * factor)));
  Scene refined = scene;
  refined.object_mesh =
      std::make_shared<const TetMesh>(make_box_mesh(base.bounds_max() - base.bounds_min(), cells));
  for (Grip& grip : refined.grips) {
    AlignedBox span{Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY)};
    for (int i : grip.nodes) {
      span.min = span.min.cwiseMin(base.rest_positions()[i]);
      span.max = span.max.cwiseMax(base.rest_positions()[i]);
    }
    const Vec3 slack = Vec3::Constant(1e-9);
    grip.nodes = NodeSelection{AlignedBox{span.min - slack, span.max + slack}, {}}.resolve(
        *refined.object_mesh);
  }
  return refined;
}

// Resets the kernel's peak resident set size (VmHWM) to the current one (Linux ≥ 4.0), so the
// next read is this size's peak. False where that is not possible: then VmHWM is the peak of
// the whole run so far.
bool reset_peak_memory() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

double peak_memory_mb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      double kb = 0;
      status >> kb;
      return kb / 1024;
    }
    status.ignore(1 << 12, '\n');
  }
  return NAN;
}

// Least-squares slope of log(time) over log(tets): time ~ tets^slope.
double growth_exponent(const std::vector<double>& tets, const std::vector<double>& times) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < tets.size(); ++k) {
    if (!(times[k] > 0)) continue;
    const double x = std::log(tets[k]), y = std::log(times[k]);
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  if (n < 2) return NAN;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The joints that move the grips' nodes by at most 1 mm: θ⁰ turned along the first joint.
Eigen::VectorXd one_mm_grip_move(const GrippedObject& object, const Positions& at) {
  const Eigen::VectorXd from = object.reference_joints();
  Eigen::VectorXd to = from;
  to[0] += 1e-3;
  Positions moved = at;
  object.carry_gripped_nodes(from, to, at, moved);
  const double largest = (moved - at).cwiseAbs().maxCoeff();
  to[0] = from[0] + 1e-3 * (1e-3 / largest);
  return to;
}

// A target change at 50k tets on a loaded 2-core machine can take over 10 s (the paper table's
// limit): the scaling table waits longer before it counts one as not reached.
constexpr double kMaxSecondsPerTarget = 60;

struct SizeRow {
  int tets = 0;
  double from_rest = NAN, from_rest_first = NAN;  // s; the first includes the symbolic analysis
  int from_rest_iterations = 0;
  double warm = NAN;  // s
  int warm_iterations = 0, warm_factorizations = 0;
  std::vector<double> target_times, newton_per_target, factorizations_per_target, steps;
  int not_reached = 0;
  double peak_mb = NAN;
};

SizeRow measure(const Scene& scene, int trials, unsigned seed) {
  SizeRow row;
  const GrippedObject object(scene);
  row.tets = object.mesh().tet_count();
  const ReducedObjective objective(object);
  const Eigen::VectorXd theta0 = object.reference_joints();
  std::vector<double> from_rest;
  std::optional<Evaluation> reference;
  for (int r = 0; r < 3; ++r) {
    const auto t0 = BenchClock::now();
    Evaluation e = objective.evaluate(theta0, object.reference_positions());
    from_rest.push_back(seconds_between(t0, BenchClock::now()));
    if (!e.statics().converged())
      throw SolverFailure("statics at the reference, " + std::to_string(row.tets) +
                          " tets: " + e.statics().reason);
    row.from_rest_iterations = e.statics().iterations;
    reference = std::move(e);
  }
  row.from_rest_first = from_rest[0];
  row.from_rest = percentile(from_rest, 0.5);

  const Eigen::VectorXd moved = one_mm_grip_move(object, reference->positions());
  std::vector<double> warm;
  for (int r = 0; r < 5; ++r) {
    Positions x = reference->positions();
    object.carry_gripped_nodes(theta0, moved, reference->positions(), x);
    const auto t0 = BenchClock::now();
    const Evaluation e = objective.evaluate(moved, x, 0, &*reference);
    warm.push_back(seconds_between(t0, BenchClock::now()));
    row.warm_iterations = e.statics().iterations;
    row.warm_factorizations = e.statics().factorizations;
  }
  row.warm = percentile(warm, 0.5);

  std::mt19937 goals(seed + 1);
  for (int trial = 0; trial < trials; ++trial) {
    ShapeTargets targets;
    if (!random_goal(objective, *reference, goals, targets)) continue;
    const StaticsTotals before = statics_totals();
    const auto reached = steps_to_1mm(objective.with_targets(targets), *reference,
                                      OptimizerKind::GaussNewton, kMaxSecondsPerTarget);
    const StaticsTotals after = statics_totals();
    if (!reached) {
      ++row.not_reached;
      continue;
    }
    row.target_times.push_back(reached->first);
    row.steps.push_back(reached->second);
    row.newton_per_target.push_back(after.iterations - before.iterations);
    row.factorizations_per_target.push_back(after.factorizations - before.factorizations);
  }
  return row;
}

}  // namespace

std::vector<int> parse_tet_counts(const std::string& text, const std::string& option) {
  std::vector<int> counts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    if (item == "mesh") {
      counts.push_back(kSceneMesh);
      start = end + 1;
      continue;
    }
    std::size_t used = 0;
    double value = NAN;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used > 0 && used + 1 == item.size() && (item.back() == 'k' || item.back() == 'K'))
      value *= 1000, ++used;
    if (used == 0 || used != item.size() || !(value >= 6 && value <= 2e6))
      throw InputError(option, "",
                       "tet counts separated by commas, each 6 to 2000k or \"mesh\" for the "
                       "scene's own (e.g. 1.5k,6k,12k)",
                       "\"" + item + "\"");
    counts.push_back(static_cast<int>(std::lround(value)));
    start = end + 1;
  }
  return counts;
}

void bench_scaling(const std::string& scene_file, const std::vector<int>& tet_counts, int trials,
                   unsigned seed, ScalingLevers levers, nlohmann::json& record) {
  Scene scene = load_scene(scene_file);
  scene.statics.krylov_steps = levers.krylov_steps;
  scene.statics.single_precision_chord = levers.single_precision_chord;
  apply_linear_solver_option(levers.linear_solver, scene);
  if (!scene.robot) throw InputError(scene_file, "robot", "a scene with a robot (missing key)");
  const auto cells = box_cells(*scene.object_mesh);
  const bool refines = std::any_of(tet_counts.begin(), tet_counts.end(),
                                   [](int count) { return count != kSceneMesh; });
  if (refines && (!cells || (scene.fixed && !scene.fixed->nodes.empty())))
    throw InputError(scene_file, "object.mesh",
                     "a box mesh without hole and no fixed nodes by index (for --sizes with tet "
                     "counts; --sizes mesh takes the scene's mesh as it is)");
  std::printf(
      "\n%s at each size (--sizes; \"mesh\": as it is): %d random reachable target sets per size, "
      "Gauss-Newton to a mean "
      "error < 1 mm; Krylov steps %s; chord and Krylov solves in %s precision\n",
      scene_file.c_str(), trials, levers.krylov_steps ? "on from 5,000 unknowns" : "off",
      levers.single_precision_chord ? "single" : "double");
  std::printf("  %7s | %-22s | %-22s | %-27s | %-13s | %-9s | %s\n", "tets", "statics from rest ms",
              "warm 1 mm grip move ms", "target change ms: med (p90)", "Newton it/fac", "GN steps",
              "peak MB");
  std::vector<double> tets, target_medians, rest_medians, warm_medians;
  for (int count : tet_counts) {
    const bool per_size = reset_peak_memory();
    SizeRow row =
        measure(count == kSceneMesh ? scene : refined_scene(scene, *cells, count), trials, seed);
    row.peak_mb = peak_memory_mb();
    std::printf(
        "  %7d | %7.1f (first %7.1f) %d it | %7.2f %2d it %d fac | %8.1f (%8.1f) %2zu/%-2d ok | "
        "%4.0f / %4.0f | %3.0f (%2.0f) | %.0f%s\n",
        row.tets, 1e3 * row.from_rest, 1e3 * row.from_rest_first, row.from_rest_iterations,
        1e3 * row.warm, row.warm_iterations, row.warm_factorizations,
        1e3 * percentile(row.target_times, 0.5), 1e3 * percentile(row.target_times, 0.9),
        row.target_times.size(), static_cast<int>(row.target_times.size()) + row.not_reached,
        percentile(row.newton_per_target, 0.5), percentile(row.factorizations_per_target, 0.5),
        percentile(row.steps, 0.5), percentile(row.steps, 1.0), row.peak_mb,
        per_size ? "" : " (whole run)");
    std::fflush(stdout);
    record["scene"] = scene_file;
    record["rows"].push_back(
        {{"tets", row.tets},
         {"from_rest_s", row.from_rest},
         {"from_rest_first_s", row.from_rest_first},
         {"warm_s", row.warm},
         {"target_median_s", percentile(row.target_times, 0.5)},
         {"target_p90_s", percentile(row.target_times, 0.9)},
         {"reached", row.target_times.size()},
         {"trials", static_cast<int>(row.target_times.size()) + row.not_reached},
         {"peak_mb", per_size ? nlohmann::json(row.peak_mb) : nlohmann::json()}});
    tets.push_back(row.tets);
    target_medians.push_back(percentile(row.target_times, 0.5));
    rest_medians.push_back(row.from_rest);
    warm_medians.push_back(row.warm);
  }
  // An exponent needs two sizes.
  if (std::set<double>(tets.begin(), tets.end()).size() >= 2) {
    record["growth"] = {{"target_change", growth_exponent(tets, target_medians)},
                        {"from_rest", growth_exponent(tets, rest_medians)},
                        {"warm", growth_exponent(tets, warm_medians)}};
    std::printf(
        "  growth exponent (time ~ tets^k, least squares on log-log): target change %.2f, "
        "statics from rest %.2f, warm re-solve %.2f\n",
        growth_exponent(tets, target_medians), growth_exponent(tets, rest_medians),
        growth_exponent(tets, warm_medians));
  }
  std::printf(
      "  Newton it/fac: statics iterations (Newton + chord) and numeric factorizations per target "
      "change, medians; peak MB: VmHWM of /proc/self/status, reset before each size\n");
}

}  // namespace shapectl::cli
