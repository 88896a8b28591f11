// Self-contact in the CLI's results (issue 34): RESULT.json's "contacts" of `statics` and `solve`
// carry "self": {"count", "min_distance"} with contact.self, its pairs in neither the obstacles'
// count nor their force. The object: the YuMi bar with a 2 mm slit through its middle
// (tests/data/slit_bar.py), its upper slab's middle pressed down onto the lower slab.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

constexpr double kDhat = 0.001;  // the default contact distance

// scenes/yumi_bar.json with the slit bar, the upper slab's middle pressed down by `press` N
// (none for 0), and contact.self.
nlohmann::json slit_bar(double press) {
  nlohmann::json scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  scene["object"]["mesh"] = {{"file", test::source_path("tests/data/slit_bar.node").string()}};
  if (press != 0)
    scene["loads"] = {{{"box", {{"min", {-0.021, -1, 0.0005}}, {"max", {0.021, 1, 0.0076}}}},
                       {"force", {0, 0, -press}}}};
  scene["contact"] = {{"self", true}};
  return scene;
}

nlohmann::json run(const TempDir& dir, const std::vector<std::string>& args) {
  const auto out = dir.path() / "result.json";
  std::filesystem::remove(out);
  std::vector<std::string> all = args;
  all.insert(all.end(), {"--out", out.string()});
  const test::CliRun r = run_cli(all);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return std::filesystem::exists(out) ? nlohmann::json::parse(test::read_text(out))
                                      : nlohmann::json();
}

// No obstacle: the obstacles' part says so, whatever the self-contact.
void expect_no_obstacle_contact(const nlohmann::json& contacts) {
  EXPECT_EQ(contacts["count"], 0);
  EXPECT_FALSE(contacts.contains("min_distance"));
  EXPECT_EQ(contacts["force_total"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(contacts["by_obstacle"], nlohmann::json::object());
}

TEST(SelfContactCli, StaticsReportsTheSlitPressedShut) {
  TempDir dir;
  const auto scene = dir.write("scene.json", slit_bar(0.5).dump(1));
  const nlohmann::json r = run(dir, {"statics", scene.string()});
  ASSERT_TRUE(r["converged"].get<bool>()) << r["reason"];
  const nlohmann::json& c = r["contacts"];
  expect_no_obstacle_contact(c);
  EXPECT_GT(c["self"]["count"].get<int>(), 0);
  const double gap = c["self"]["min_distance"].get<double>();
  EXPECT_GT(gap, 0);
  EXPECT_LT(gap, kDhat);
}

TEST(SelfContactCli, AnOpenSlitHasNoSelfContactAndNoDistance) {
  TempDir dir;
  const auto scene = dir.write("scene.json", slit_bar(0).dump(1));
  const nlohmann::json r = run(dir, {"statics", scene.string()});
  ASSERT_TRUE(r["converged"].get<bool>()) << r["reason"];
  expect_no_obstacle_contact(r["contacts"]);
  EXPECT_EQ(r["contacts"]["self"], nlohmann::json({{"count", 0}}));
  // Without contact.self: no contact term, no "contacts".
  nlohmann::json without = slit_bar(0);
  without.erase("contact");
  const auto plain = dir.write("plain.json", without.dump(1));
  EXPECT_FALSE(run(dir, {"statics", plain.string()}).contains("contacts"));
}

TEST(SelfContactCli, SolveReportsTheSelfContactOfItsBestJoints) {
  TempDir dir;
  const auto scene = dir.write("scene.json", slit_bar(0.5).dump(1));
  // Targets at the pressed equilibrium: reached at the reference joints, slit shut.
  const nlohmann::json statics = run(dir, {"statics", scene.string()});
  nlohmann::json targets = nlohmann::json::array();
  for (int i = 0; i < 306; i += 17)
    targets.push_back({{"node", i}, {"position", statics["positions"][i]}});
  const auto targets_file = dir.write("targets.json", nlohmann::json{{"targets", targets}}.dump());
  const nlohmann::json r = run(dir, {"solve", scene.string(), "--targets", targets_file.string(),
                                     "--max-iterations", "2"});
  ASSERT_TRUE(r.contains("contacts")) << r.dump();
  expect_no_obstacle_contact(r["contacts"]);
  EXPECT_GT(r["contacts"]["self"]["count"].get<int>(), 0);
  EXPECT_LT(r["contacts"]["self"]["min_distance"].get<double>(), kDhat);
}

}  // namespace
}  // namespace shapectl
