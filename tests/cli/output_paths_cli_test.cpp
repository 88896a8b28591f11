// Issue 36 item 12: every command checks that its output paths can be written before it reads
// its inputs or computes anything: exit 1 naming the option and the path, nothing written.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

struct OutputOption {
  std::vector<std::string> command;  // everything but the option; inputs that do not exist
  std::string option;
};

// Every option naming a file to write, on a command line whose inputs are all missing: had the
// command read them first, the error would name an input instead.
std::vector<OutputOption> output_options(const std::filesystem::path& dir) {
  const std::string none = (dir / "none.json").string(), good = (dir / "good.json").string();
  const std::vector<std::string> statics = {"statics", none, "--out", good};
  const std::vector<std::string> solve = {"solve", none, "--targets", none, "--out", good};
  const std::vector<std::string> calibrate = {"calibrate", none,    "--observations",
                                              none,        "--out", good};
  const std::vector<std::string> author = {"author",          (dir / "none.urdf").string(),
                                           "--box",           "0.3,0.03,0.03",
                                           "--end-effectors", "a=b",
                                           "--out",           good};
  return {{statics, "--out"},
          {statics, "--vtu"},
          {statics, "--surface"},
          {solve, "--out"},
          {solve, "--vtu"},
          {solve, "--surface"},
          {{"kinematics", (dir / "none.urdf").string()}, "--out"},
          {calibrate, "--out"},
          {calibrate, "--report"},
          {author, "--out"},
          {author, "--spheres-out"},
          {author, "--report"},
          {{"bench", none}, "--json"},
          {{"run", none, "--targets", none}, "--log"},
          // --rate out of range too: without the check on --log, serve would exit naming --rate
          // (checked after --log), not start serving.
          {{"serve", none, "--rate", "1000"}, "--log"}};
}

TEST(OutputPathsCli, AnOutputIntoAMissingFolderIsRefusedFirstNamingTheOption) {
  const TempDir dir;
  const auto bad = dir.path() / "missing" / "x.ply";
  for (const OutputOption& o : output_options(dir.path())) {
    std::vector<std::string> args = o.command;
    if (args.size() > 2 && args[args.size() - 2] == o.option)
      args.erase(args.end() - 2, args.end());  // replaced by the bad one
    args.insert(args.end(), {o.option, bad.string()});
    const test::CliRun run = run_cli(args);
    EXPECT_EQ(run.exit_code, 1) << args[0] << " " << o.option << ": " << run.err;
    EXPECT_NE(run.err.find(o.option + ": " + bad.string() + ": cannot write: directory '" +
                           bad.parent_path().string() + "' does not exist"),
              std::string::npos)
        << args[0] << " " << o.option << ": " << run.err;
  }
  // Nothing was written, not even a temporary.
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(OutputPathsCli, AnOutputThatIsAFolderIsRefusedAndKept) {
  const TempDir dir;
  const auto folder = dir.path() / "out.json";
  dir.write("out.json/keep.txt", "kept");
  const test::CliRun run =
      run_cli({"statics", (dir.path() / "none.json").string(), "--out", folder.string()});
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("--out: " + folder.string() + ": cannot write: it is a directory"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(test::read_text(folder / "keep.txt"), "kept");
}

}  // namespace
}  // namespace shapectl
