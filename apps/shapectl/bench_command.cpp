// placeholder: being written
#include "commands.hpp"
namespace shapectl::cli {
void add_bench_command(CLI::App&) {}
}  // namespace shapectl::cli
