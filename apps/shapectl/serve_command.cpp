// placeholder: being written
#include "commands.hpp"
namespace shapectl::cli {
void add_serve_command(CLI::App&) {}
}  // namespace shapectl::cli
