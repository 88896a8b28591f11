// placeholder: being written
#include "commands.hpp"
namespace shapectl::cli {
void add_solve_command(CLI::App&) {}
}  // namespace shapectl::cli
