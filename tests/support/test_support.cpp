#include "support/test_support.hpp"

#include <shapectl/io/input_error.hpp>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace shapectl::test {

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() /
          ("shapectl_test_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + "_" +
           std::to_string(rd() % 100000));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path TempDir::write(const std::string& name, const std::string& text) const {
  const auto file = path_ / name;
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file) << text;
  return file;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string bundled_scene_text(const std::string& name) {
  std::string text = read_text(source_path("scenes/" + name));
  const std::string data = source_path("data").string();
  for (std::size_t at = text.find("../data"); at != std::string::npos;
       at = text.find("../data", at + 1))
    text.replace(at, 7, data);
  return text;
}

std::string clamped_bar_scene_with(const std::string& keys) {
  std::string text = kClampedBarScene;
  text.replace(text.find("\"gravity\""), 9, keys + ", \"gravity\"");
  return text;
}

std::vector<std::string> cli_command(const std::vector<std::string>& args) {
  std::vector<std::string> command = {SHAPECTL_CLI};
  command.insert(command.end(), args.begin(), args.end());
  return command;
}

pid_t start_process(const std::vector<std::string>& command, const std::filesystem::path& out,
                    const std::filesystem::path& err, const std::function<void()>& in_child) {
  // Everything the child needs is made before fork: it only opens, redirects and execs.
  std::vector<std::string> copy = command;
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    if (in_child) in_child();
    const int out_fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = err.empty() ? out_fd : open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out_fd, 1);
    dup2(err_fd, 2);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

int wait_for_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

CliRun run_cli(const std::vector<std::string>& args,
               const std::filesystem::path& working_directory) {
  TempDir dir;
  const auto out_file = dir.path() / "stdout";
  const auto err_file = dir.path() / "stderr";
  const std::string cwd = working_directory.string();  // made before fork
  auto enter = [&cwd] {
    if (!cwd.empty() && chdir(cwd.c_str()) != 0) _exit(126);
  };
  CliRun run;
  run.exit_code = wait_for_exit(start_process(cli_command(args), out_file, err_file, enter));
  run.out = read_text(out_file);
  run.err = read_text(err_file);
  return run;
}

std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(SHAPECTL_SOURCE_DIR) / relative;
}

std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace shapectl::test
