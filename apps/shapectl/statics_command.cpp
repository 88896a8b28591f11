// shapectl statics SCENE.json [--joints JOINTS.json] --out RESULT.json [--vtu DEFORMED.vtu]
//   [--surface SURFACE.ply|SURFACE.obj]
// Solves the object's static equilibrium (held by fixed nodes, or by the robot at the given
// joints) and writes the deformed positions.
#include <chrono>
#include <iostream>
#include <optional>

#include <shapectl/io/atomic_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/io/vtu_writer.hpp>
#include <shapectl/robot/joints_file.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/gripped_object.hpp>

#include "commands.hpp"
#include "linear_solver_option.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"
#include "surface_option.hpp"

namespace shapectl::cli {

namespace {

struct StaticsArgs {
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::string scene;
  std::string joints;
  std::string out;
  std::string vtu;
  std::string surface;
  std::string linear_solver;
};

// Writes RESULT.json (and the VTU) even when Newton failed (with the contacts at its state when
// the scene has obstacles), so the failure can be inspected,
// but never with a non-finite number, and with --vtu or --surface all files or none.
// `seconds`: set-up and Newton, reported on stderr (not in RESULT.json: it stays reproducible).
// `contact`: the contact term at x (posed at the joints, at the solve's stiffness); none without
// obstacles.
void write_outputs(const StaticsArgs& args, const StaticsResult& r, const Scene& scene,
                   const ObjectStatics& statics, const std::optional<ObstacleContact>& contact,
                   const Positions& rest, const Positions& x, nlohmann::json result,
                   double seconds) {
  const TetMesh& mesh = statics.mesh();
  result["converged"] = r.converged();
  result["status"] = to_string(r.status);
  result["reason"] = r.reason;
  result["iterations"] = r.iterations;
  result["residual"] = r.residual;
  result["energy"] = r.energy;
  result["loads_total"] = vec3_json(scene.loads_total());
  if (auto contacts = contacts_json(contact ? &*contact : nullptr, statics.self_contact(), x);
      !contacts.is_null())
    result["contacts"] = std::move(contacts);
  result["positions"] = positions_json(x);
  require_finite(result, "statics", r.reason);
  std::vector<FileContent> files = {{args.out, to_pretty_json(result)}};
  if (!args.vtu.empty()) {
    std::vector<std::array<int, 4>> tets;
    for (const auto& t : mesh.tets()) tets.push_back(t.nodes);
    files.push_back({args.vtu, vtu_text(x, tets, {{"displacement", x - rest}})});
  }
  if (!args.surface.empty()) files.push_back(surface_file(args.surface, mesh, x));
  write_files_atomically(files);
  std::cerr << "statics: " << r.reason << " (" << mesh.tet_count() << " tets, " << mesh.node_count()
            << " nodes; set-up and Newton " << 1e3 * seconds << " ms)\n";
  if (!r.converged()) throw SolverFailure(r.reason);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void run_statics(const StaticsArgs& args) {
  check_surface_option("statics", args.surface);
  check_linear_solver_option("statics", args.linear_solver);
  Scene scene = load_scene(args.scene);
  apply_linear_solver_option(args.linear_solver, scene);
  print_scene_notes(scene, args.package_paths);
  const auto start = std::chrono::steady_clock::now();  // the files are read
  const Positions rest = scene.world_rest_positions();
  Positions x = rest;
  if (!scene.robot) {
    if (!args.joints.empty())
      throw InputError(args.joints, "", "joints given, but the scene has no robot");
    ObjectStatics statics(scene);
    const StaticsResult r = statics.solve(x);
    write_outputs(args, r, scene, statics, statics.contact_terms(r.contact_scale).obstacles, rest,
                  x, nlohmann::json::object(), seconds_since(start));
    return;
  }
  GrippedObject object(scene);
  Eigen::VectorXd joints = object.reference_joints();
  if (!args.joints.empty()) joints = load_joints_file(args.joints, object.robot(), joints);
  const ObjectState state = object.solve_from(joints, x);
  write_outputs(args, state.statics(), scene, object.statics(), object.contact_at(state), rest,
                state.positions(), robot_json(scene, joints), seconds_since(start));
}

}  // namespace

void add_statics_command(CLI::App& app) {
  auto args = std::make_shared<StaticsArgs>();
  auto* cmd = app.add_subcommand("statics", "Solve the object's static equilibrium");
  cmd->add_option("scene", args->scene, "SCENE.json")->required();
  cmd->add_option("--joints", args->joints,
                  "JOINTS.json {\"joints\": {name: rad}}, or a result of statics, solve or run "
                  "(default: the reference joints)");
  cmd->add_option("--out", args->out, "RESULT.json to write")->required()->check(writable_output());
  cmd->add_option("--vtu", args->vtu, "also write the deformed mesh as VTU (ParaView)")
      ->check(writable_output());
  add_surface_option(*cmd, args->surface);
  add_linear_solver_option(*cmd, args->linear_solver);
  add_package_path_option(*cmd, args->package_paths);
  cmd->callback([args] { run_statics(*args); });
}

}  // namespace shapectl::cli
