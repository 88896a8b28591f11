#pragma once
// Helpers shared by the tests: temporary files and running the CLI.
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

struct CliRun {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs the built `shapectl` binary with `args` (each passed as one argument, no shell).
CliRun run_cli(const std::vector<std::string>& args);

// Path of a file in the source tree, e.g. source_path("scenes/yumi_bar.json").
std::filesystem::path source_path(const std::string& relative);

// The message of the InputError `f` throws, or "" when it throws none.
std::string input_error_of(const std::function<void()>& f);

}  // namespace shapectl::test
