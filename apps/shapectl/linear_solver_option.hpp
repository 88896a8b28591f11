#pragma once
// --linear-solver NAME of statics, solve, calibrate, bench, run and serve: the scene's
// "statics.linear_solver" overridden from the command line.
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include <shapectl/sim/scene.hpp>

namespace shapectl::cli {

void add_linear_solver_option(CLI::App& cmd, std::string& name);
// Checks the name before any work: InputError naming --linear-solver of `command` and the
// choices unless it is one of them. Nothing to check when `name` is empty (not given).
void check_linear_solver_option(const std::string& command, const std::string& name);
// What `name` (checked) sets: nothing when empty (not given), else the back-end, nullopt for
// "auto" (ControllerOptions::linear_solver).
std::optional<std::optional<CholeskyBackend>> linear_solver_override(const std::string& name);
// The scene with the back-end `name` (checked) sets; the scene's own when `name` is empty.
void apply_linear_solver_option(const std::string& name, Scene& scene);

}  // namespace shapectl::cli
