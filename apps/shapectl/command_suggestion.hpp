#pragma once
// A mistyped subcommand ("solv") answered with the nearest name ("did you mean 'solve'?") rather
// than CLI11's "The following arguments were not expected".
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace shapectl::cli {

// Levenshtein distance: the fewest single-character insertions, deletions and substitutions
// that turn `a` into `b`.
std::size_t edit_distance(std::string_view a, std::string_view b);

// The name in `names` that `typed` is most likely a typo of: the one it begins (when only one
// does), else the nearest within 2 edits and fewer edits than half its length; none otherwise.
std::optional<std::string> nearest_name(std::string_view typed,
                                        const std::vector<std::string>& names);

// The message for a first argument that is neither an option nor one of `app`'s subcommands:
// "unknown command 'solv'; did you mean 'solve'? (commands: statics, ...)"; none when the
// command line starts with a known command or an option.
std::optional<std::string> unknown_command_message(CLI::App& app, int argc, char** argv);

}  // namespace shapectl::cli
