// "loads" and "regions" through the CLI: results carry loads_total, bad input names its field.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

// The clamped test bar (81 nodes, x from −0.16 to 0.16 m) with `extra` keys added.
std::string bar_with(const std::string& extra) { return test::clamped_bar_scene_with(extra); }

const std::string kTip = R"({"box": {"min": [0.159, -1, -1], "max": [1, 1, 1]}, )";
const std::string kSoft = R"({"youngs_modulus": 5e4, "poisson_ratio": 0.3, "density": 40})";

// How far the free end (x = 0.16 m at rest) of the scene in `scene_file` sinks in its statics
// result: the mean drop of its nodes' z, m.
double tip_sag(const std::filesystem::path& scene_file, const nlohmann::json& result) {
  const Scene scene = load_scene(scene_file);
  double sum = 0;
  int count = 0;
  for (int i = 0; i < scene.object_mesh->node_count(); ++i)
    if (scene.object_mesh->rest_positions()[i].x() > 0.159) {
      sum += scene.object_mesh->rest_positions()[i].z() - result["positions"][i][2].get<double>();
      ++count;
    }
  return sum / count;
}

struct Statics {
  test::CliRun run;
  nlohmann::json result;
  double tip_sag = 0;  // m, when it converged
};

Statics statics(const TempDir& dir, const std::string& scene_text) {
  const auto scene = dir.write("scene.json", scene_text);
  const auto out = dir.path() / "result.json";
  std::filesystem::remove(out);
  Statics s{run_cli({"statics", scene.string(), "--out", out.string()}), {}};
  if (std::filesystem::exists(out)) s.result = nlohmann::json::parse(test::read_text(out));
  if (s.run.exit_code == 0) s.tip_sag = tip_sag(scene, s.result);
  return s;
}

TEST(LoadsCli, StaticsResultsGiveLoadsTotalAndTheLoadBendsTheBar) {
  TempDir dir;
  const Statics plain = statics(dir, test::kClampedBarScene);
  ASSERT_EQ(plain.run.exit_code, 0) << plain.run.err;
  EXPECT_EQ(plain.result["loads_total"], nlohmann::json({0.0, 0.0, 0.0}));
  const Statics loaded = statics(dir, bar_with(R"("loads": [)" + kTip +
                                               R"("force": [0, 0, -0.05]}, {"nodes": [80, 79], )" +
                                               R"("force": [0.01, 0, -0.02]}])"));
  ASSERT_EQ(loaded.run.exit_code, 0) << loaded.run.err;
  ASSERT_TRUE(loaded.result["converged"].get<bool>());
  const std::vector<double> total = loaded.result["loads_total"];
  EXPECT_NEAR(total[0], 0.01, 1e-15);
  EXPECT_EQ(total[1], 0.0);
  EXPECT_NEAR(total[2], -0.07, 1e-15);
  // 70 mN down at the tip of a bar weighing 113 mN: beam theory says 2.7× the sag (the tip force
  // adds P L³/3EI to the weight's W L³/8EI).
  EXPECT_GT(loaded.tip_sag, 2 * plain.tip_sag);
  EXPECT_GT(plain.tip_sag, 0.001);
}

TEST(LoadsCli, RegionsOfASofterMaterialMakeTheBarSagMore) {
  TempDir dir;
  const Statics plain = statics(dir, test::kClampedBarScene);
  const Statics soft_root = statics(
      dir, bar_with(R"("regions": [{"box": {"min": [-1, -1, -1], "max": [0, 1, 1]}, "material": )" +
                    kSoft + "}]"));
  ASSERT_EQ(soft_root.run.exit_code, 0) << soft_root.run.err;
  ASSERT_TRUE(soft_root.result["converged"].get<bool>());
  // A quarter of the stiffness in the half next to the clamp, which carries most of the bending
  // moment: beam theory says 3.8× the sag under the bar's own weight.
  EXPECT_GT(soft_root.tip_sag, 2 * plain.tip_sag);
}

TEST(LoadsCli, TheBundledTipWeightSceneHangsItsWeightFromTheFreeEnd) {
  TempDir dir;
  const auto out = dir.path() / "weight.json";
  const auto scene = test::source_path("scenes/foam_bar_tip_weight.json");
  const auto run = run_cli({"statics", scene.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(test::read_text(out));
  EXPECT_TRUE(result["converged"].get<bool>());
  EXPECT_NEAR(result["loads_total"][2].get<double>(), -0.0981, 1e-15);
  const auto plain_out = dir.path() / "plain.json";
  const auto plain_scene = test::source_path("scenes/foam_bar_clamped.json");
  ASSERT_EQ(run_cli({"statics", plain_scene.string(), "--out", plain_out.string()}).exit_code, 0);
  // 98 mN at the tip of a 113 mN bar: beam theory says 3.3× the sag.
  EXPECT_GT(tip_sag(scene, result),
            2 * tip_sag(plain_scene, nlohmann::json::parse(test::read_text(plain_out))));
}

TEST(LoadsCli, BadLoadsAndRegionsAreBadInputNamingTheField) {
  TempDir dir;
  const std::string region_box = R"({"box": {"min": [-1, -1, -1], "max": [0, 1, 1]}, "material": )";
  for (const auto& [extra, where, what] : std::vector<std::array<std::string, 3>>{
           {R"("loads": [{"box": {"min": [0.5, -1, -1], "max": [1, 1, 1]}, "force": [0, 0, -1]}])",
            "loads[0].box", "a box around at least one node"},
           {R"("loads": [{"nodes": [3, 81], "force": [0, 0, -1]}])", "loads[0].nodes[1]",
            "expected a whole number from 0 to 80"},
           {R"("loads": [{"nodes": [], "force": [0, 0, -1]}])", "loads[0].nodes",
            "at least one node index"},
           {R"("loads": [{"nodes": [3], "force": [0, 0, -1e999]}])", "loads[0].force[2]",
            "expected a finite number"},
           {R"("loads": [{"nodes": [3], "force": [0, 0, 1e10]}])", "loads[0].force",
            "a force of length at most"},
           {R"("loads": [{"nodes": [3]}])", "loads[0].force", "missing"},
           {R"("loads": [{"nodes": [3], "force": [0, 0, 1], "weight": 2}])", "loads[0].weight",
            "unknown key"},
           {R"("regions": [{"box": {"min": [0.5, -1, -1], "max": [1, 1, 1]}, "material": )" +
                kSoft + "}]",
            "regions[0].box", "a box around the centroid of at least one element"},
           {R"("regions": [)" + region_box + kSoft + "}, " + region_box +
                R"({"youngs_modulus": -5, "poisson_ratio": 0.3, "density": 40}}])",
            "regions[1].material.youngs_modulus", "expected a positive number"},
           {R"("regions": [)" + region_box +
                R"({"youngs_modulus": 5e4, "poisson_ratio": 0.5, "density": 40}}])",
            "regions[0].material.poisson_ratio", "between 0 and 0.5"},
           {R"("regions": [)" + region_box + R"({"mu": 1e4, "density": 40}}])",
            "regions[0].material.kappa", "missing"}}) {
    const Statics s = statics(dir, bar_with(extra));
    EXPECT_EQ(s.run.exit_code, 1) << extra << "\n" << s.run.err;
    EXPECT_NE(s.run.err.find("scene.json: " + where + ": "), std::string::npos) << where << ":\n"
                                                                                << s.run.err;
    EXPECT_NE(s.run.err.find(what), std::string::npos) << what << ":\n" << s.run.err;
  }
}

TEST(LoadsCli, SolveWithAHangingWeightReachesTargetsOfTheLoadedBarAndReportsTheLoad) {
  TempDir dir;
  // The YuMi bar with 50 g hanging from its middle.
  nlohmann::json scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  scene["loads"] = {
      {{"box", {{"min", {-0.01, -1, -1}}, {"max", {0.01, 1, 1}}}}, {"force", {0, 0, -0.49}}}};
  const auto scene_file = dir.write("loaded.json", scene.dump());
  const auto goal_out = dir.path() / "goal.json";
  nlohmann::json joints = scene["robot"]["reference_joints"];
  joints["yumi_joint_1_l"] = joints["yumi_joint_1_l"].get<double>() + 0.08;
  joints["yumi_joint_2_r"] = joints["yumi_joint_2_r"].get<double>() + 0.05;
  const auto joints_file = dir.write("joints.json", nlohmann::json{{"joints", joints}}.dump());
  const auto goal_run = run_cli({"statics", scene_file.string(), "--joints", joints_file.string(),
                                 "--out", goal_out.string()});
  ASSERT_EQ(goal_run.exit_code, 0) << goal_run.err;
  const auto goal = nlohmann::json::parse(test::read_text(goal_out));
  EXPECT_NEAR(goal["loads_total"][2].get<double>(), -0.49, 1e-15);
  nlohmann::json targets = nlohmann::json::array();
  for (int i = 0; i < 425; i += 17)
    targets.push_back({{"node", i}, {"position", goal["positions"][i]}});
  const auto targets_file = dir.write("targets.json", nlohmann::json{{"targets", targets}}.dump());
  const auto out = dir.path() / "solve.json";
  const auto run = run_cli(
      {"solve", scene_file.string(), "--targets", targets_file.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(test::read_text(out));
  EXPECT_EQ(result["loads_total"], goal["loads_total"]);
  // The targets are an equilibrium of the loaded model: reachable, through sensitivities that
  // the constant load leaves as they were.
  EXPECT_LT(result["error_max"].get<double>(), 1e-3);
}

}  // namespace
}  // namespace shapectl
