// placeholder: being written
#include "commands.hpp"
namespace shapectl::cli {
void add_link_commands(CLI::App&) {}
}  // namespace shapectl::cli
