#include "linear_solver_option.hpp"

#include <stdexcept>

#include <shapectl/io/input_error.hpp>
#include <shapectl/linalg/cholesky_backend.hpp>

namespace shapectl::cli {

void add_linear_solver_option(CLI::App& cmd, std::string& name) {
  cmd.add_option("--linear-solver", name,
                 "the statics' sparse Cholesky, over the scene's statics.linear_solver: " +
                     linear_solver_choices());
}

void check_linear_solver_option(const std::string& command, const std::string& name) {
  CholeskyBackend backend;
  if (!name.empty() && name != "auto" && !parse(name, &backend))
    throw InputError(command, "--linear-solver", linear_solver_choices(), name);
}

std::optional<std::optional<CholeskyBackend>> linear_solver_override(const std::string& name) {
  if (name.empty()) return std::nullopt;
  CholeskyBackend backend;
  if (parse(name, &backend)) return std::optional{backend};
  if (name == "auto") return std::optional<CholeskyBackend>{};
  throw std::logic_error("--linear-solver " + name + ": not checked");
}

void apply_linear_solver_option(const std::string& name, Scene& scene) {
  if (const auto backend = linear_solver_override(name)) scene.statics.backend = *backend;
}

}  // namespace shapectl::cli
