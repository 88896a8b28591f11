// The link area's subcommands: run (headless controller + robot link), egm-sim (a stand-in for
// the robot controller's EGM side) and replay (check and re-stream a session log).
#include "commands.hpp"

namespace shapectl::cli {

void add_run_command(CLI::App& app);      // run_command.cpp
void add_egm_sim_command(CLI::App& app);  // egm_sim_command.cpp
void add_replay_command(CLI::App& app);   // replay_command.cpp

void add_link_commands(CLI::App& app) {
  add_run_command(app);
  add_egm_sim_command(app);
  add_replay_command(app);
}

}  // namespace shapectl::cli
