#pragma once
// Ctrl-C / SIGTERM for the long-running commands (run, egm-sim, replay): the first signal asks
// the command to stop cleanly (disarm, let the robot brake), a second one ends the process.
namespace shapectl {

void install_stop_signal_handlers();
bool stop_signal_received();

}  // namespace shapectl
