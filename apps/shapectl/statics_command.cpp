// shapectl statics SCENE.json --out RESULT.json [--vtu DEFORMED.vtu]
// Solves the object's static equilibrium and writes the deformed positions.
#include <iostream>

#include <shapectl/io/json_output.hpp>
#include <shapectl/io/vtu_writer.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "commands.hpp"

namespace shapectl::cli {

namespace {

struct StaticsArgs {
  std::string scene;
  std::string out;
  std::string vtu;
};

void run_statics(const StaticsArgs& args) {
  const Scene scene = load_scene(args.scene);
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  const nlohmann::json result = {
      {"converged", r.converged()}, {"status", to_string(r.status)}, {"reason", r.reason},
      {"iterations", r.iterations}, {"residual", r.residual},        {"energy", r.energy},
      {"positions", positions_to_json(x)}};
  write_json_file(args.out, result);
  if (!args.vtu.empty()) {
    std::vector<std::array<int, 4>> tets;
    for (const auto& t : statics.mesh().tets()) tets.push_back(t.nodes);
    const Positions rest = scene.world_rest_positions();
    write_vtu(args.vtu, x, tets, {{"displacement", x - rest}});
  }
  std::cerr << "statics: " << r.reason << " (" << statics.mesh().tet_count() << " tets, "
            << statics.mesh().node_count() << " nodes)\n";
  if (!r.converged()) throw SolverFailure(r.reason);
}

}  // namespace

void add_statics_command(CLI::App& app) {
  auto args = std::make_shared<StaticsArgs>();
  auto* cmd = app.add_subcommand("statics", "Solve the object's static equilibrium");
  cmd->add_option("scene", args->scene, "SCENE.json")->required();
  cmd->add_option("--out", args->out, "RESULT.json to write")->required();
  cmd->add_option("--vtu", args->vtu, "also write the deformed mesh as VTU (ParaView)");
  cmd->callback([args] { run_statics(*args); });
}

}  // namespace shapectl::cli
