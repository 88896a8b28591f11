#pragma once
// The scaling table of `shapectl bench --sizes 1.5k,6k,...`: one scene's box mesh refined to
// about each tet count, with target changes, warm re-solves, statics from rest, peak memory
// and how the times grow with the tet count. The size "mesh" is the scene's own mesh, of any
// kind (a TetGen or Gmsh mesh too), as it is.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace shapectl::cli {

// The size that stands for the scene's own mesh, unrefined ("mesh" in --sizes).
constexpr int kSceneMesh = 0;

// "1.5k,6k,12k,mesh" → {1500, 6000, 12000, kSceneMesh}. Throws InputError naming `option` for
// anything else.
std::vector<int> parse_tet_counts(const std::string& text, const std::string& option);

// Solver levers a run can turn off, to measure what each saves.
struct ScalingLevers {
  bool krylov_steps = true;            // conjugate-gradient steps (`--no-krylov`)
  bool single_precision_chord = true;  // chord/Krylov solves in float (`--double-chord`)
  std::string linear_solver;           // `--linear-solver`, checked (empty: the scene's)
};

// Runs and prints the table for the scene file (to refine, its object must be a box mesh
// without hole); `trials` random reachable target sets per size. The figures also go to
// `record` (bench_json.hpp).
void bench_scaling(const std::string& scene_file, const std::vector<int>& tet_counts, int trials,
                   unsigned seed, ScalingLevers levers, nlohmann::json& record);

}  // namespace shapectl::cli
