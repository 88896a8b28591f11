// "obstacles" and "contact" through the CLI (issue 34): statics results carry the contacts, bad
// input names its field and exits 1.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

// The clamped test bar (x from −0.16 to 0.16 m, bottom face at z = −0.015 m) with `extra` keys.
std::string bar_with(const std::string& extra) { return test::clamped_bar_scene_with(extra); }

// A table 0.5 mm under the bar: its free end sags onto it.
const std::string kTable =
    R"("obstacles": [{"name": "table", "plane": {"point": [0, 0, -0.0155], "normal": [0, 0, 1]}}])";

struct Statics {
  test::CliRun run;
  nlohmann::json result;
};

Statics statics(const TempDir& dir, const std::string& scene_text) {
  const auto scene = dir.write("scene.json", scene_text);
  const auto out = dir.path() / "result.json";
  std::filesystem::remove(out);
  Statics s{run_cli({"statics", scene.string(), "--out", out.string()}), {}};
  if (std::filesystem::exists(out)) s.result = nlohmann::json::parse(test::read_text(out));
  return s;
}

TEST(ObstaclesCli, StaticsOnATableReportsTheContacts) {
  TempDir dir;
  const Statics plain = statics(dir, test::kClampedBarScene);
  ASSERT_EQ(plain.run.exit_code, 0) << plain.run.err;
  EXPECT_FALSE(plain.result.contains("contacts"));  // no obstacles: nothing to report
  const Statics s = statics(dir, bar_with(kTable + R"(, "contact": {"distance": 0.001})"));
  ASSERT_EQ(s.run.exit_code, 0) << s.run.err;
  ASSERT_TRUE(s.result["converged"].get<bool>());
  const nlohmann::json& c = s.result["contacts"];
  EXPECT_GT(c["count"].get<int>(), 0);
  const double gap = c["min_distance"].get<double>();
  EXPECT_GT(gap, 0);
  EXPECT_LE(gap, 0.001);
  // The table carries part of the bar's weight (113 mN), the clamp the rest; it pushes up only.
  const double up = c["force_total"][2].get<double>();
  EXPECT_GT(up, 0.01);
  EXPECT_LT(up, 0.113);
  EXPECT_EQ(c["by_obstacle"]["table"]["force"], c["force_total"]);
  EXPECT_EQ(c["by_obstacle"]["table"]["count"], c["count"]);
  // Every node above the table.
  for (const auto& p : s.result["positions"]) EXPECT_GT(p[2].get<double>(), -0.0155);
}

// A given contact.stiffness is where κ starts (docs/contact.md, "Adaptive stiffness"): one far
// too small for the bar's sag onto the table is raised until no gap is below d̂/100, and the
// contacts report the κ the result is at.
TEST(ObstaclesCli, StaticsRaiseATooSmallStiffnessAndReportIt) {
  TempDir dir;
  const Statics s =
      statics(dir, bar_with(kTable + R"(, "contact": {"distance": 0.001, "stiffness": 1e-4})"));
  ASSERT_EQ(s.run.exit_code, 0) << s.run.err;
  ASSERT_TRUE(s.result["converged"].get<bool>());
  EXPECT_NE(s.result["reason"].get<std::string>().find("contact stiffness ×"), std::string::npos)
      << s.result["reason"];
  const nlohmann::json& c = s.result["contacts"];
  EXPECT_GT(c["count"].get<int>(), 0);
  EXPECT_GT(c["stiffness"].get<double>(), 1e-4);
  EXPECT_GE(c["min_distance"].get<double>(), 1e-5);
  // The table still carries part of the weight, upwards.
  EXPECT_GT(c["force_total"][2].get<double>(), 0.01);
}

TEST(ObstaclesCli, AnObstacleOutOfReachGivesNoContactsAndNoDistance) {
  TempDir dir;
  const Statics s =
      statics(dir,
              bar_with(R"("obstacles": [{"sphere": {"center": [0, 0, -0.5], "radius": 0.03}}])"));
  ASSERT_EQ(s.run.exit_code, 0) << s.run.err;
  const nlohmann::json& c = s.result["contacts"];
  EXPECT_EQ(c["count"], 0);
  EXPECT_FALSE(c.contains("min_distance"));  // no pair within d̂: no number, never inf or NaN
  EXPECT_EQ(c["by_obstacle"]["obstacle 1"]["force"], nlohmann::json({0.0, 0.0, 0.0}));
}

// A peg whose position was typed in mm lands 390 m away: legal, but it can never be touched.
TEST(ObstaclesCli, AnObstacleFarBeyondTheObjectIsWarnedAbout) {
  TempDir dir;
  const std::string peg = R"("obstacles": [{"name": "peg", "box": {"size": [0.02, 0.02, 0.1], )"
                          R"("pose": {"position": [390, 0, 0]}}}])";
  const Statics far = statics(dir, bar_with(peg));
  ASSERT_EQ(far.run.exit_code, 0) << far.run.err;
  EXPECT_NE(far.run.err.find("warning: "), std::string::npos) << far.run.err;
  EXPECT_NE(far.run.err.find("obstacles[0] ('peg'): 390 m from the object"), std::string::npos)
      << far.run.err;
  // The same peg 0.2 m from the bar: no warning.
  const std::string near = R"("obstacles": [{"name": "peg", "box": {"size": [0.02, 0.02, 0.1], )"
                           R"("pose": {"position": [0.4, 0, 0]}}}])";
  const Statics close = statics(dir, bar_with(near));
  ASSERT_EQ(close.run.exit_code, 0) << close.run.err;
  EXPECT_EQ(close.run.err.find("obstacles[0]"), std::string::npos) << close.run.err;
}

TEST(ObstaclesCli, BadObstaclesAndContactAreBadInputNamingTheField) {
  TempDir dir;
  dir.write("open.obj", "v 0 0 -1\nv 1 0 -1\nv 0 1 -1\nf 1 2 3\n");
  const std::string plane = R"({"plane": {"point": [0, 0, -0.5], "normal": [0, 0, 1]}})";
  auto obstacles = [](const std::string& list) { return R"("obstacles": [)" + list + "]"; };
  for (const auto& [extra, where, what] : std::vector<std::array<std::string, 3>>{
           {obstacles(R"({"plane": {"point": [0, 0, -0.5], "normal": [0, 0, 0]}})"),
            "obstacles[0].plane.normal", "a non-zero normal"},
           {obstacles(R"({"sphere": {"center": [0, 0, -0.5], "radius": -1}})"),
            "obstacles[0].sphere.radius", "expected a positive number"},
           {obstacles(R"({"box": {"size": [0.1, 0, 0.1]}})"), "obstacles[0].box.size[1]",
            "expected a positive number"},
           {obstacles(R"({"sphere": {"center": [0, 0, -1e999], "radius": 0.1}})"),
            "obstacles[0].sphere.center[2]", "expected a finite number"},
           {obstacles(R"({"sphere": {"center": [5000, 0, 0], "radius": 0.1}})"),
            "obstacles[0].sphere.center", "a point of length at most 1000 m"},
           {obstacles(R"({"capsule": {"a": [0, 0, -1], "b": [0, 0, -1], "radius": 0.1}})"),
            "obstacles[0].capsule.b", "a point other than \"a\""},
           {obstacles(R"({"box": {"size": [0.1, 0.1, 0.1], "pose": {"position": [0, 0, -1], )"
                      R"("rpy": [0, 0, "x"]}}})"),
            "obstacles[0].box.pose.rpy[2]", "expected a number"},
           {obstacles(R"({"link": "gripper_l", "sphere": {"center": [0, 0, -1], "radius": 0.1}})"),
            "obstacles[0].link", "an obstacle on a link needs a \"robot\""},
           {obstacles(R"({"cylinder": {"radius": 0.1}})"), "obstacles[0].cylinder", "unknown key"},
           {obstacles(R"({"name": "table"})"), "obstacles[0]", "exactly one of"},
           {obstacles(R"({"name": "a", "plane": {"point": [0, 0, -1], "normal": [0, 0, 1]}}, )"
                      R"({"name": "a", "sphere": {"center": [0, 0, -1], "radius": 0.1}})"),
            "obstacles[1].name", "a name no other obstacle has"},
           {obstacles(R"({"mesh": {"file": "open.obj"}})"), "obstacles[0].mesh.file",
            "not a closed surface"},
           {obstacles(R"({"mesh": {"file": "open.obj", "units": "inch"}})"),
            "obstacles[0].mesh.units", "\"m\", \"cm\" or \"mm\""},
           {obstacles(R"({"name": "ball", "sphere": {"center": [0, 0, 0], "radius": 0.02}})"),
            "obstacles[0] ('ball')", "touches or intersects"},
           {obstacles(plane) + R"(, "contact": {"distance": -0.001})", "contact.distance",
            "expected a positive number"},
           {obstacles(plane) + R"(, "contact": {"friction": -0.1})", "contact.friction",
            "expected a non-negative number"},
           {obstacles(plane) + R"(, "contact": {"friction": "0.3"})", "contact.friction",
            "expected a number"},
           {obstacles(plane) + R"(, "contact": {"self": 1})", "contact.self", "true or false"},
           {obstacles(plane) + R"(, "contact": {"robot": true})", "contact.robot",
            "contact with the robot needs a \"robot\""},
           {obstacles(plane) + R"(, "contact": {"stiffness": 0})", "contact.stiffness",
            "expected a positive number"},
           {obstacles(plane) + R"(, "contact": {"gap": 0.1})", "contact.gap", "unknown key"},
           // d̂ in metres meant as mm: the barrier would act across the whole bar.
           {obstacles(plane) + R"(, "contact": {"distance": 1})", "contact.distance",
            "was it meant in mm?"}}) {
    const Statics s = statics(dir, bar_with(extra));
    EXPECT_EQ(s.run.exit_code, 1) << extra << "\n" << s.run.err;
    EXPECT_NE(s.run.err.find("scene.json: " + where + ": "), std::string::npos) << where << ":\n"
                                                                                << s.run.err;
    EXPECT_NE(s.run.err.find(what), std::string::npos) << what << ":\n" << s.run.err;
  }
}

// A 100 × 60 × 40 mm block on a plane tilted 20° about y (tan α = 0.364), turned with it, its
// bottom 0.5 mm above it; gravity straight down. Friction `mu`.
std::string block_on_slope(double mu) {
  const double a = 20 * M_PI / 180, up = 0.0205;  // the block's centre above the plane
  return R"({"object": {"mesh": {"box": {"size": [0.1, 0.06, 0.04], "cells": [5, 3, 2]}},
               "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "density": 500},
               "pose": {"position": [)" +
         std::to_string(std::sin(a) * up) + ", 0, " + std::to_string(std::cos(a) * up) +
         R"(], "rpy": [0, )" + std::to_string(a) + R"(, 0]}},
    "gravity": [0, 0, -9.81],
    "obstacles": [{"name": "slope", "plane": {"point": [0, 0, 0], "normal": [)" +
         std::to_string(std::sin(a)) + ", 0, " + std::to_string(std::cos(a)) + R"(]}}],
    "contact": {"distance": 0.001, "friction": )" +
         std::to_string(mu) + "}}";
}

TEST(ObstaclesCli, FrictionHoldsABlockOnASlopeOrTheStaticsSaysItSlides) {
  TempDir dir;
  const Statics held = statics(dir, block_on_slope(0.5));
  ASSERT_EQ(held.run.exit_code, 0) << held.run.err;
  EXPECT_TRUE(held.result["converged"].get<bool>());
  EXPECT_GT(held.result["contacts"]["count"].get<int>(), 0);
  const Statics slides = statics(dir, block_on_slope(0.2));
  EXPECT_EQ(slides.run.exit_code, 2) << slides.run.err;
  EXPECT_NE(slides.run.err.find("slides along obstacle 'slope'"), std::string::npos)
      << slides.run.err;
  ASSERT_TRUE(slides.result.contains("converged")) << "the failed state is written too";
  EXPECT_FALSE(slides.result["converged"].get<bool>());
  EXPECT_EQ(slides.result["status"], "not converged");
}

// The bundled peg scene's purpose: bend the bar around the peg. Centre-line targets make a
// parabola whose vertex rests against the peg's near face and whose ends pass its far face;
// the solve reaches it with the peg pushing back and no node inside the peg.
TEST(ObstaclesCli, TheBarWrapsThePeg) {
  TempDir dir;
  const auto scene = dir.write("peg.json", test::bundled_scene_text("yumi_bar_peg.json"));
  const auto rest_out = dir.path() / "rest.json";
  ASSERT_EQ(run_cli({"statics", scene.string(), "--out", rest_out.string()}).exit_code, 0);
  const auto rest = nlohmann::json::parse(test::read_text(rest_out));
  // The scene: bar centre at x = 0.39047, z = 0.25527, along y (±0.16 m), 3 cm thick; the peg
  // a 2 × 2 cm box at x = 0.42047 (faces at 0.41047 and 0.43047), |y| ≤ 0.01.
  const double centre_x = 0.39047, centre_z = 0.25527, near_face = 0.41047, far_face = 0.43047;
  const double vertex_x = near_face - 0.015 - 0.0003, depth = 0.04;  // the gap at rest ~ d̂/2
  nlohmann::json line = nlohmann::json::array();
  std::vector<std::array<double, 3>> axis;
  for (const auto& p : rest["positions"])
    if (std::abs(p[0].get<double>() - centre_x) < 1e-3 &&
        std::abs(p[2].get<double>() - centre_z) < 1e-3)
      axis.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
  ASSERT_EQ(axis.size(), 17u);  // 16 cells along the bar
  std::sort(axis.begin(), axis.end(), [](const auto& a, const auto& b) { return a[1] < b[1]; });
  for (const auto& p : axis)
    line.push_back({vertex_x + depth * std::pow(p[1] / 0.16, 2), p[1], p[2]});
  const auto targets = dir.write("wrap.json", nlohmann::json{{"centerline", line}}.dump());
  const auto out = dir.path() / "solve.json";
  const auto run =
      run_cli({"solve", scene.string(), "--targets", targets.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(test::read_text(out));
  EXPECT_LT(result["error_mean"].get<double>(), 1e-3) << run.err;
  const nlohmann::json& peg = result["contacts"]["by_obstacle"]["peg"];
  EXPECT_GE(peg["count"].get<int>(), 10);
  EXPECT_LT(peg["force"][0].get<double>(), -0.5);  // the peg pushes the bar back, newtons
  double ends_x = 0, middle_x = -INFINITY;         // the end faces' mean x; the middle's front
  int end_nodes = 0;
  for (std::size_t i = 0; i < result["positions"].size(); ++i) {
    const auto& p = result["positions"][i];
    const double x = p[0].get<double>(), y = p[1].get<double>(), z = p[2].get<double>();
    const double rest_y = rest["positions"][i][1].get<double>();
    const bool inside_peg =
        x > near_face && x < far_face && std::abs(y) < 0.01 && std::abs(z - centre_z) < 0.05;
    EXPECT_FALSE(inside_peg) << x << " " << y << " " << z;
    if (std::abs(rest_y) > 0.155) ends_x += x, ++end_nodes;
    if (std::abs(rest_y) < 0.01) middle_x = std::max(middle_x, x);
  }
  ASSERT_GT(end_nodes, 0);
  EXPECT_GT(ends_x / end_nodes, far_face);  // the ends past the peg...
  EXPECT_LT(middle_x, near_face);           // ...the middle in front of it: wrapped
}

TEST(ObstaclesCli, TheBundledPegSceneSolvesClearOfThePeg) {
  TempDir dir;
  const Statics s = statics(dir, test::bundled_scene_text("yumi_bar_peg.json"));
  ASSERT_EQ(s.run.exit_code, 0) << s.run.err;
  EXPECT_TRUE(s.result["converged"].get<bool>());
  EXPECT_EQ(s.result["contacts"]["by_obstacle"]["peg"]["count"], 0);  // 5 mm in front of the bar
}

// The 1 m cable lying on the table, both ends gripped: an S drawn on the table (the centre-line
// of its equilibrium with both wrists turned 0.1 rad: reachable by construction) is reached
// with the cable still resting on the table.
TEST(ObstaclesCli, TheCableOnTheTableReachesACentreLineS) {
  TempDir dir;
  const std::string text = test::bundled_scene_text("yumi_cable_table.json");
  const auto scene = dir.write("cable.json", text);
  nlohmann::json joints = nlohmann::json::parse(text)["robot"]["reference_joints"];
  for (const char* wrist : {"yumi_joint_7_l", "yumi_joint_7_r"})
    joints[wrist] = joints[wrist].get<double>() + 0.1;
  const auto joints_file = dir.write("joints.json", nlohmann::json{{"joints", joints}}.dump());
  const auto goal_out = dir.path() / "goal.json";
  const auto goal_run = run_cli(
      {"statics", scene.string(), "--joints", joints_file.string(), "--out", goal_out.string()});
  ASSERT_EQ(goal_run.exit_code, 0) << goal_run.err;
  const auto goal = nlohmann::json::parse(test::read_text(goal_out));
  ASSERT_GT(goal["contacts"]["count"].get<int>(), 0);
  // The centre-line nodes of the 50 × 2 × 2 box: j = k = 1, i = 0..50.
  nlohmann::json line = nlohmann::json::array();
  for (int i = 0; i <= 50; ++i) line.push_back(goal["positions"][i + 51 * (1 + 3 * 1)]);
  const auto targets = dir.write("s.json", nlohmann::json{{"centerline", line}}.dump());
  const auto out = dir.path() / "solve.json";
  const auto run =
      run_cli({"solve", scene.string(), "--targets", targets.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto result = nlohmann::json::parse(test::read_text(out));
  EXPECT_LT(result["error_mean"].get<double>(), 2e-3) << run.err;
  EXPECT_GT(result["contacts"]["count"].get<int>(), 0);
  const double table = 0.1095;  // the scene's table plane
  for (const auto& p : result["positions"]) EXPECT_GT(p[2].get<double>(), table);
}

}  // namespace
}  // namespace shapectl
