#pragma once
// Output file options are checked when the command line is parsed, before any input is read or
// anything computed: a result that cannot be written is known in milliseconds, not after the
// solve (the files are still written atomically afterwards: io/atomic_file.hpp).
#include <CLI/CLI.hpp>

namespace shapectl::cli {

// For `->check(...)` on an option naming a file to write: its directory exists and takes a new
// file, and it is not a directory. CLI11 prefixes the option's name, e.g. exit 1 with
// "--out: out/r.json: cannot write: directory 'out' does not exist".
CLI::Validator writable_output();

}  // namespace shapectl::cli
