#pragma once
// Each subcommand lives in its own file and registers itself on the app.
#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

namespace shapectl::cli {

// A computation that ran but failed (not converged, inverted, singular): exit code 2.
class SolverFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void add_statics_command(CLI::App& app);
void add_kinematics_command(CLI::App& app);
void add_author_command(CLI::App& app);
void add_solve_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_serve_command(CLI::App& app);  // server area (GUI)
void add_link_commands(CLI::App& app);  // link area: run, egm-sim, replay

}  // namespace shapectl::cli
