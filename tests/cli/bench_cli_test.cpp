// `shapectl bench --sizes`: the scaling table (its timings are measurements for
// docs/benchmarks.md, not assertions), its --json record and its option's errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>

#include "support/test_support.hpp"

namespace shapectl::test {
namespace {

TEST(BenchCli, ScalingTableHasARowPerSizeAndTheGrowthExponents) {
  TempDir dir;
  const auto json = dir.path() / "bench.json";
  const std::string bar = source_path("scenes/yumi_bar.json").string();
  const CliRun run =
      run_cli({"bench", bar, "--sizes", "0.4k,1.5k", "--trials", "2", "--json", json.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // 0.4k: the bar's 16 × 4 × 4 cells scaled by (400 / 1536)^⅓ → 10 × 3 × 3 cells, 540 tets.
  EXPECT_TRUE(std::regex_search(run.out, std::regex(R"(\n +540 \|)"))) << run.out;
  EXPECT_TRUE(std::regex_search(run.out, std::regex(R"(\n +1536 \|)"))) << run.out;
  // Both sizes reached the targets of both trials, and three finite exponents follow.
  // (The count is padded: "2/2  ok".)
  EXPECT_TRUE(std::regex_search(run.out, std::regex(R"(\b2/2 +ok)"))) << run.out;
  EXPECT_FALSE(std::regex_search(run.out, std::regex(R"(\b[01]/2 +ok)"))) << run.out;
  EXPECT_TRUE(std::regex_search(
      run.out, std::regex(R"(target change -?\d+\.\d+, statics from rest -?\d+\.\d+, warm )")))
      << run.out;
  // --json: the same rows (scripts/bench_table.py reads them), times in seconds.
  const auto record = nlohmann::json::parse(read_text(json));
  const auto& rows = record["sizes"]["rows"];
  ASSERT_EQ(rows.size(), 2u) << record.dump(1);
  EXPECT_EQ(rows[0]["tets"], 540);
  EXPECT_EQ(rows[1]["tets"], 1536);
  for (const auto& row : rows) {
    EXPECT_EQ(row["reached"], 2);
    EXPECT_EQ(row["trials"], 2);
    EXPECT_GT(row["target_median_s"].get<double>(), 0);
    EXPECT_LE(row["target_median_s"].get<double>(), row["target_p90_s"].get<double>());
  }
  EXPECT_TRUE(record["sizes"]["growth"]["target_change"].is_number()) << record.dump(1);
  EXPECT_TRUE(record["date"].is_string());
}

TEST(BenchCli, SizesMeshMeasuresTheScenesOwnMeshOfAnyKind) {
  // The frame (a box with a hole, not refinable) as it is: one row, and no growth exponent,
  // which needs two sizes.
  const CliRun run = run_cli({"bench", source_path("scenes/yumi_frame.json").string(), "--sizes",
                              "mesh", "--trials", "2"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::smatch row;
  ASSERT_TRUE(std::regex_search(run.out, row, std::regex(R"(\n +(\d+) \|.*\b2/2 +ok)"))) << run.out;
  EXPECT_GT(std::stoi(row[1]), 100) << run.out;
  EXPECT_EQ(run.out.find("growth exponent"), std::string::npos) << run.out;
}

TEST(BenchCli, BadSizesAreRefusedNamingTheOptionAndTheItem) {
  const CliRun run = run_cli({"bench", "--sizes", "1.5k,lots"});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("--sizes"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("\"lots\""), std::string::npos) << run.err;
}

TEST(BenchCli, SizesNeedABoxMeshWithoutHole) {
  const CliRun run =
      run_cli({"bench", source_path("scenes/yumi_frame.json").string(), "--sizes", "1k"});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("object.mesh"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace shapectl::test
