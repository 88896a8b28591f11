// Implausible scenes: each is an InputError (exit 1 in the CLI) or a warning naming the field;
// none loads silently. The bundled scenes and the in-code test scene pass without a warning.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/scene_checks.hpp>

#include "support/test_support.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

using Json = nlohmann::json;
using test::TempDir;

std::string error_of(const std::function<void()>& f) { return test::input_error_of(f); }

// A bundled scene as JSON, its relative paths made absolute so it loads from a temp dir.
Json bundled(const std::string& name) { return Json::parse(test::bundled_scene_text(name)); }

// The foam bar clamped at its -x end, with the given mesh (no robot).
Json clamped_bar(const Json& mesh) {
  return Json{{"object",
               {{"mesh", mesh},
                {"material", {{"youngs_modulus", 2e5}, {"poisson_ratio", 0.3}, {"density", 40}}}}},
              {"fixed", {{"box", {{"min", {-0.17, -1, -1}}, {"max", {-0.13, 1, 1}}}}}}};
}

// A closed 300 x 30 x 30 box surface centred at the origin, coordinates in the file's unit.
std::string box_obj(double length, double side) {
  std::string text;
  for (int i = 0; i < 8; ++i)
    text += "v " + std::to_string((i & 1 ? 0.5 : -0.5) * length) + " " +
            std::to_string((i & 2 ? 0.5 : -0.5) * side) + " " +
            std::to_string((i & 4 ? 0.5 : -0.5) * side) + "\n";
  return text + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

struct Loaded {
  std::string error;  // empty when the scene loaded
  Scene scene;
};

Loaded load(const TempDir& dir, const Json& scene) {
  Loaded out;
  const auto file = dir.write("scene.json", scene.dump(2));
  out.error = error_of([&] { out.scene = load_scene(file); });
  return out;
}

bool any_contains(const std::vector<std::string>& lines, const std::string& part) {
  for (const auto& line : lines)
    if (line.find(part) != std::string::npos) return true;
  return false;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines) out += line + "\n";
  return out;
}

TEST(SceneChecks, BundledScenesLoadWithoutWarningsAndTheirGripsSitAtTheTools) {
  for (const char* name : {"foam_bar_clamped.json", "foam_bar_tip_weight.json", "yumi_bar.json",
                           "yumi_frame.json", "yumi_bar_u.json"}) {
    const Scene scene = load_scene(test::source_path(std::string("scenes/") + name));
    EXPECT_TRUE(scene.warnings.empty()) << name << ":\n" << joined(scene.warnings);
    for (const GripPlacement& p : grip_placements(scene)) {
      EXPECT_GE(p.node_count, grip_warning_node_count) << name;
      EXPECT_LT(p.tool_distance, grip_warning_distance) << name;
    }
  }
}

TEST(SceneChecks, TheInCodeTwoArmSceneIsPlausible) {
  const Scene scene = test::two_arm_scene();
  EXPECT_TRUE(check_scene(scene).empty()) << joined(check_scene(scene));
  const auto lines = describe_grips(scene);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].rfind("grips[0] ('left'): ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find(std::to_string(scene.grips[0].nodes.size()) + " nodes"),
            std::string::npos)
      << lines[0];
}

TEST(SceneChecks, OutOfLimitReferenceJointIsAnErrorNamingTheJointAndItsLimits) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  scene["robot"]["reference_joints"]["yumi_joint_2_l"] = 3.0;
  const std::string error = load(dir, scene).error;
  EXPECT_NE(error.find("scene.json: robot.reference_joints.yumi_joint_2_l: expected a value within "
                       "the joint's limits ["),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("0.7592"), std::string::npos) << error;  // the upper limit, as in the URDF
  EXPECT_NE(error.find("got 3"), std::string::npos) << error;
}

TEST(SceneChecks, FixedJointOutOfLimitsNamesTheFixedJointsField) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  scene["robot"]["fixed_joints"]["gripper_l_joint"] = 0.5;
  const std::string error = load(dir, scene).error;
  EXPECT_NE(error.find(
                "robot.fixed_joints.gripper_l_joint: expected a value within the joint's limits"),
            std::string::npos)
      << error;
}

TEST(SceneChecks, ReferenceJointInsideTheLimitMarginIsAWarning) {
  Scene scene = test::two_arm_scene();
  scene.grips.clear();  // the tool moves with the joint: keep only the joint in question
  scene.robot->reference_joints[0] = 1.98;  // l1: limits [-2, 2], margin 0.05
  const auto warnings = check_scene(scene);
  EXPECT_TRUE(any_contains(
      warnings,
      "two_arm_scene: robot.reference_joints.l1: 1.98 is within robot.joint_limit_margin"))
      << joined(warnings);
}

TEST(SceneChecks, SelfCollidingReferencePoseIsAnErrorNamingTheClosestPair) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  for (auto& [name, value] : scene["robot"]["reference_joints"].items()) value = 0.0;
  const std::string error = load(dir, scene).error;
  EXPECT_EQ(
      error.rfind(
          (dir.path() / "scene.json").string() +
              ": robot.reference_joints: the robot collides with itself at the reference joints",
          0),
      0u)
      << error;
  EXPECT_NE(error.find("the closest pair is a sphere of '"), std::string::npos) << error;
  EXPECT_NE(error.find("clearance -"), std::string::npos) << error;
}

TEST(SceneChecks, GripRegionCatchingNoNodeIsAnErrorNamingTheGrip) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  // World coordinates typed where object coordinates belong: beyond the bar's end.
  scene["grips"][1]["region"]["box"] = {{"min", {0.3, -0.02, 0.2}}, {"max", {0.4, 0.02, 0.3}}};
  const std::string error = load(dir, scene).error;
  EXPECT_NE(
      error.find(
          "scene.json: grips[1]: the grip region contains no node of the mesh (its nodes span"),
      std::string::npos)
      << error;
}

TEST(SceneChecks, ObjectFarFromBothGrippersIsAnErrorNamingTheGripAndDistance) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  scene["object"]["pose"]["position"][0] =
      scene["object"]["pose"]["position"][0].get<double>() + 0.45;
  const std::string error = load(dir, scene).error;
  EXPECT_NE(error.find("scene.json: grips[0] ('left'): its centre (the mean of its "),
            std::string::npos)
      << error;
  EXPECT_NE(
      error.find(
          "from the end effector's tool point at the reference joints, expected at most 50.0 mm"),
      std::string::npos)
      << error;
  // The distance is the offset: 450 mm, give or take the few mm the grips sit from the tools.
  const auto at = error.find(" nodes) is ");
  ASSERT_NE(at, std::string::npos) << error;
  EXPECT_NEAR(std::stod(error.substr(at + 11)), 450, 15) << error;
}

TEST(SceneChecks, GripAFewCentimetresFromItsToolIsAWarningNamingEachGrip) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  scene["object"]["pose"]["position"][2] =
      scene["object"]["pose"]["position"][2].get<double>() + 0.03;
  const Loaded loaded = load(dir, scene);
  ASSERT_EQ(loaded.error, "");
  EXPECT_TRUE(any_contains(loaded.scene.warnings, "grips[0] ('left'): its centre"))
      << joined(loaded.scene.warnings);
  EXPECT_TRUE(any_contains(loaded.scene.warnings, "grips[1] ('right'): its centre"))
      << joined(loaded.scene.warnings);
}

TEST(SceneChecks, GripOfOneNodeIsAWarning) {
  Scene scene = test::two_arm_scene();
  scene.grips[0].nodes.resize(1);
  EXPECT_TRUE(
      any_contains(check_scene(scene), "two_arm_scene: grips[0] ('left'): catches only 1 node(s)"))
      << joined(check_scene(scene));
}

TEST(SceneChecks, MeshInMillimetresWithoutUnitsIsAnErrorSuggestingUnits) {
  const TempDir dir;
  dir.write("bar.obj", box_obj(300, 30));
  const std::string error = load(dir, clamped_bar("bar.obj")).error;
  EXPECT_NE(error.find("scene.json: object.mesh: the object is "), std::string::npos) << error;
  EXPECT_NE(error.find("\"units\": \"mm\""), std::string::npos) << error;
  // Checked before TetGen: a volume bound meant for metres names the units, not the bound.
  const std::string bounded =
      load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"max_tet_volume", 1e-7}})).error;
  EXPECT_NE(bounded.find("scene.json: object.mesh: the object is "), std::string::npos) << bounded;
  // The same from the CLI: exit 1, no result file.
  const auto out = dir.path() / "result.json";
  const auto run =
      test::run_cli({"statics", (dir.path() / "scene.json").string(), "--out", out.string()});
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("object.mesh: the object is "), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(SceneChecks, MeshInMillimetresWithUnitsOrScaleLoadsAtItsTrueSize) {
  const TempDir dir;
  dir.write("bar.obj", box_obj(300, 30));
  for (const Json& mesh :
       {Json{{"file", "bar.obj"}, {"units", "mm"}}, Json{{"file", "bar.obj"}, {"scale", 0.001}}}) {
    const Loaded loaded = load(dir, clamped_bar(mesh));
    ASSERT_EQ(loaded.error, "") << mesh;
    const Vec3 size =
        loaded.scene.object_mesh->bounds_max() - loaded.scene.object_mesh->bounds_min();
    EXPECT_LT((size - Vec3(0.3, 0.03, 0.03)).norm(), 1e-9) << mesh << ": " << size.transpose();
    EXPECT_NEAR(loaded.scene.object_mesh->total_volume(), 0.3 * 0.03 * 0.03, 1e-12) << mesh;
    EXPECT_TRUE(loaded.scene.warnings.empty()) << joined(loaded.scene.warnings);
  }
  // A centimetre mesh read as centimetres is the same bar.
  dir.write("bar_cm.obj", box_obj(30, 3));
  const Loaded cm = load(dir, clamped_bar(Json{{"file", "bar_cm.obj"}, {"units", "cm"}}));
  ASSERT_EQ(cm.error, "");
  EXPECT_NEAR(cm.scene.object_mesh->bounds_max().x(), 0.15, 1e-9);
}

TEST(SceneChecks, VolumeMeshInMillimetresIsScaledNodeByNode) {
  const TempDir dir;
  dir.write("tet.msh",
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 100 0 0\n3 0 100 0\n"
            "4 0 0 100\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n");
  Json scene = clamped_bar(Json{{"file", "tet.msh"}, {"units", "mm"}});
  scene["fixed"] = {{"nodes", {0, 1, 2}}};
  const Loaded loaded = load(dir, scene);
  ASSERT_EQ(loaded.error, "");
  EXPECT_LT((loaded.scene.object_mesh->rest_positions()[3] - Vec3(0, 0, 0.1)).norm(), 1e-12);
  EXPECT_NEAR(loaded.scene.object_mesh->total_volume(), 0.1 * 0.1 * 0.1 / 6, 1e-15);
  // Unscaled its bounding box is 100 m a side, 173 m across: refused, suggesting units.
  scene["object"]["mesh"] = "tet.msh";
  EXPECT_NE(load(dir, scene).error.find("object.mesh: the object is 173 m across"),
            std::string::npos)
      << load(dir, scene).error;
}

TEST(SceneChecks, MaxTetVolumeOfAScaledMeshIsInCubicMetres) {
  const TempDir dir;
  dir.write("bar.obj", box_obj(300, 30));
  // 2.7e-4 m^3 of bar in tets of at most 1e-7 m^3: at least 2,700 of them. Read unscaled the
  // bound would allow the whole 2.7e5 "m^3" bar in one tet per 1e-7 — far too many to ask for.
  const Loaded loaded =
      load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"units", "mm"}, {"max_tet_volume", 1e-7}}));
  ASSERT_EQ(loaded.error, "");
  EXPECT_GE(loaded.scene.object_mesh->tet_count(), 2700);
  for (const TetRest& t : loaded.scene.object_mesh->tets()) EXPECT_LT(t.volume, 2e-7);
}

TEST(SceneChecks, BadUnitsAreRefusedNamingTheField) {
  const TempDir dir;
  dir.write("bar.obj", box_obj(300, 30));
  EXPECT_NE(load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"units", "inch"}}))
                .error.find("scene.json: object.mesh.units: expected \"m\", \"cm\" or \"mm\""),
            std::string::npos);
  EXPECT_NE(load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"units", "mm"}, {"scale", 0.001}}))
                .error.find("scene.json: object.mesh.scale: give \"units\" or \"scale\", not both"),
            std::string::npos);
  EXPECT_NE(load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"scale", -1}}))
                .error.find("scene.json: object.mesh.scale: expected a positive number"),
            std::string::npos);
  // A box is in metres already: no units.
  EXPECT_NE(load(dir,
                 clamped_bar(Json{{"box", {{"size", {0.32, 0.03, 0.03}}, {"cells", {8, 2, 2}}}},
                                  {"units", "mm"}}))
                .error.find("scene.json: object.mesh.units: unknown key"),
            std::string::npos);
}

TEST(SceneChecks, ObjectFarLargerThanTheRobotIsAnError) {
  const TempDir dir;
  Json scene = bundled("yumi_bar.json");
  scene["object"]["mesh"]["box"]["size"] = {9.0, 0.03, 0.03};
  const std::string error = load(dir, scene).error;
  EXPECT_NE(error.find("scene.json: object.mesh: the object is 9"), std::string::npos) << error;
  EXPECT_NE(error.find("far larger than the robot could hold"), std::string::npos) << error;
}

TEST(SceneChecks, LargeTetCountIsAWarningWithTheExpectedTimeAndHowToCoarsen) {
  const TempDir dir;
  const Loaded loaded =
      load(dir, clamped_bar(Json{{"box", {{"size", {0.32, 0.03, 0.03}}, {"cells", {40, 8, 8}}}}}));
  ASSERT_EQ(loaded.error, "");
  ASSERT_EQ(loaded.scene.warnings.size(), 1u) << joined(loaded.scene.warnings);
  const std::string& warning = loaded.scene.warnings[0];
  EXPECT_NE(warning.find("scene.json: object.mesh: 15360 tetrahedra: expect about "),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("object.mesh.box.cells"), std::string::npos) << warning;
  // Its reference times are the benchmarks' (expected_seconds_per_target_change), not a copy.
  EXPECT_NE(warning.find("(1,536 tets take ~15 ms, 12,288 ~0.21 s, 51,714 ~1.4 s)"),
            std::string::npos)
      << warning;
  // A surface mesh's advice is its TetGen volume bound.
  dir.write("bar.obj", box_obj(300, 30));
  const Loaded fine =
      load(dir, clamped_bar(Json{{"file", "bar.obj"}, {"units", "mm"}, {"max_tet_volume", 2e-8}}));
  ASSERT_EQ(fine.error, "");
  EXPECT_GT(fine.scene.object_mesh->tet_count(), tet_warning_count);
  EXPECT_TRUE(any_contains(fine.scene.warnings, "object.mesh.max_tet_volume"))
      << joined(fine.scene.warnings);
}

TEST(SceneChecks, ExpectedTimeGrowsWithTheTetCountThroughTheBenchmarks) {
  EXPECT_NEAR(expected_seconds_per_target_change(1536), 0.015, 1e-12);
  EXPECT_NEAR(expected_seconds_per_target_change(12288), 0.21, 1e-12);
  EXPECT_NEAR(expected_seconds_per_target_change(51714), 1.4, 1e-12);
  // Between and beyond the benchmarks: growing, without a jump at 12,288.
  EXPECT_LT(expected_seconds_per_target_change(6000), expected_seconds_per_target_change(12287));
  EXPECT_NEAR(expected_seconds_per_target_change(12287), 0.21, 1e-3);
  EXPECT_GT(expected_seconds_per_target_change(100000), 1.4);
  EXPECT_LT(expected_seconds_per_target_change(500), 0.015);
}

// The CLI refuses each implausible robot scene before it computes anything: exit 1, the field
// in the message, no result written — never an exit-0 colliding or out-of-limit result.
TEST(SceneChecks, StaticsAndSolveRefuseImplausibleScenesWithExitOne) {
  struct Case {
    std::string name;
    std::function<void(Json&)> edit;
    std::string field;
  };
  const std::vector<Case> cases = {
      {"out of limits", [](Json& s) { s["robot"]["reference_joints"]["yumi_joint_2_l"] = 3.0; },
       "robot.reference_joints.yumi_joint_2_l"},
      {"self-colliding",
       [](Json& s) {
         for (auto& [k, v] : s["robot"]["reference_joints"].items()) v = 0.0;
       },
       "robot.reference_joints: the robot collides"},
      {"far from grippers",
       [](Json& s) {
         s["object"]["pose"]["position"][0] =
             s["object"]["pose"]["position"][0].get<double>() + 0.45;
       },
       "grips[0] ('left')"}};
  for (const Case& c : cases) {
    const TempDir dir;
    Json scene = bundled("yumi_bar.json");
    c.edit(scene);
    const auto file = dir.write("scene.json", scene.dump());
    const auto targets =
        dir.write("targets.json", R"({"targets": [{"node": 0, "position": [0.4, 0.1, 0.3]}]})");
    const auto out = dir.path() / "result.json";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"statics", file.string(), "--out", out.string()},
          std::vector<std::string>{"solve", file.string(), "--targets", targets.string(), "--out",
                                   out.string()}}) {
      const auto run = test::run_cli(args);
      EXPECT_EQ(run.exit_code, 1) << c.name << " " << args[0] << ": " << run.err;
      EXPECT_NE(run.err.find(c.field), std::string::npos)
          << c.name << " " << args[0] << ": " << run.err;
      EXPECT_FALSE(std::filesystem::exists(out)) << c.name << " " << args[0];
    }
  }
}

}  // namespace
}  // namespace shapectl
