#pragma once
// Helpers shared by the tests: temporary files, bundled scenes and running the CLI.
#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace shapectl::test {

// A fresh directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  // Writes `text` to `name` inside the directory and returns its full path.
  std::filesystem::path write(const std::string& name, const std::string& text) const;

 private:
  std::filesystem::path path_;
};

std::string read_text(const std::filesystem::path& file);

// scenes/<name> as text with its "../data" paths made absolute, so it loads from any directory.
std::string bundled_scene_text(const std::string& name);

struct CliRun {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs the built `shapectl` binary with `args` (each passed as one argument, no shell), in
// `working_directory` if given (else the test's), for relative paths.
CliRun run_cli(const std::vector<std::string>& args,
               const std::filesystem::path& working_directory = {});

// The built `shapectl` followed by `args`: a command line for start_process.
std::vector<std::string> cli_command(const std::vector<std::string>& args);
// Starts `command` (the program is looked up on PATH unless it is a path; no shell) in a child
// process, its stdout going to `out` and its stderr to `err` (empty: to `out` as well).
// `in_child` runs in the child before the program (setrlimit, ...). Returns the child's pid.
pid_t start_process(const std::vector<std::string>& command, const std::filesystem::path& out,
                    const std::filesystem::path& err = {},
                    const std::function<void()>& in_child = {});
// Waits for the child `pid` to end: its exit code, or 128 + the signal that ended it.
int wait_for_exit(pid_t pid);

// A foam bar clamped at one end, 9 × 3 × 3 nodes (81; its surface 144 triangles): scene JSON
// for tests that need a small robot-less scene file.
inline constexpr const char* kClampedBarScene = R"({
  "object": {
    "mesh": {"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}},
    "material": {"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40}
  },
  "gravity": [0, 0, -9.81],
  "fixed": {"box": {"min": [-0.17, -1, -1], "max": [-0.15, 1, 1]}}
})";

// kClampedBarScene with `keys` (JSON members, e.g. R"("loads": [...])") added before "gravity".
std::string clamped_bar_scene_with(const std::string& keys);

// Path of a file in the source tree, e.g. source_path("scenes/yumi_bar.json").
std::filesystem::path source_path(const std::string& relative);

// The message of the InputError `f` throws, or "" when it throws none.
std::string input_error_of(const std::function<void()>& f);

}  // namespace shapectl::test
