// shapectl: find robot joint angles that give an elastic object the shape you ask for.
#include <csignal>
#include <iostream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/runtime/runtime_policy.hpp>

#include "command_suggestion.hpp"
#include "commands.hpp"
#include "shapectl_version.hpp"

int main(int argc, char** argv) {
  // A file size limit (ulimit -f) makes a result write fail with an error, not kill us midway.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"shapectl: interactive robotic shape control of elastic objects"};
  app.set_version_flag("--version", std::string("shapectl ") + SHAPECTL_VERSION + " (git " +
                                        SHAPECTL_GIT_REVISION + ")");
  app.require_subcommand(1);
  shapectl::cli::add_statics_command(app);
  shapectl::cli::add_kinematics_command(app);
  shapectl::cli::add_author_command(app);
  shapectl::cli::add_solve_command(app);
  shapectl::cli::add_calibrate_command(app);
  shapectl::cli::add_bench_command(app);
  shapectl::cli::add_serve_command(app);
  shapectl::cli::add_link_commands(app);
  if (const auto unknown = shapectl::cli::unknown_command_message(app, argc, argv)) {
    std::cerr << "error: " << *unknown << "\n";
    return 1;  // as CLI11's own parse errors
  }
  try {
    // Threads, OpenBLAS's idle threads, the heap (docs/runtime.md): before any command runs.
    shapectl::runtime::apply_runtime_policy(shapectl::runtime::settings_from_environment());
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  } catch (const shapectl::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const shapectl::cli::SolverFailure& e) {
    std::cerr << "solver failure: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // a bug in shapectl, never bad input or a failed solve
    std::cerr << "internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
