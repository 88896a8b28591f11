#pragma once
// --log-max-mb and --log-keep of the commands that write a session log (`run`, `serve`): the
// size cap and rotation of io/session_log.
#include <CLI/CLI.hpp>

#include <shapectl/io/session_log.hpp>

namespace shapectl::cli {

void add_session_log_options(CLI::App& cmd, SessionLogLimits& limits);

}  // namespace shapectl::cli
