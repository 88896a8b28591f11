// The scene's "obstacles" and "contact" (issue 34): every shape read into the world frame, and
// the scene writer keeping an obstacle's mesh file reachable from where it writes.
#include <shapectl/scene_io/scene_file.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <shapectl/scene_io/scene_writer.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

// A 10 mm cube drawn in millimetres, corner at the origin, faces outward.
constexpr const char* kCubeObj = R"(v 0 0 0
v 10 0 0
v 10 10 0
v 0 10 0
v 0 0 10
v 10 0 10
v 10 10 10
v 0 10 10
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
)";

// The clamped test bar (x ±0.16, y and z ±0.015 m) with obstacles of every kind clear of it.
std::string scene_with_obstacles() {
  std::string text = test::kClampedBarScene;
  text.replace(text.find("\"gravity\""), 9, R"("obstacles": [
    {"name": "table", "plane": {"point": [0, 0, -0.1], "normal": [0, 0, 2]}},
    {"name": "peg", "box": {"size": [0.02, 0.04, 0.06],
                            "pose": {"position": [0, 0.1, 0], "rpy": [0, 0, 1.5707963267948966]}}},
    {"sphere": {"center": [0.3, 0, 0], "radius": 0.03}},
    {"name": "rod", "capsule": {"a": [0, -0.1, -0.05], "b": [0, 0.1, -0.05], "radius": 0.01}},
    {"name": "fixture", "mesh": {"file": "meshes/cube.obj", "units": "mm",
                                 "pose": {"position": [0, 0, 0.05]}}}],
  "contact": {"distance": 0.002, "self": false, "robot": false, "friction": 0, "stiffness": 50,
              "sweep_steps": 12},
  "gravity")");
  return text;
}

TEST(ObstaclesScene, EveryShapeIsReadInTheWorldFrame) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "meshes");
  dir.write("meshes/cube.obj", kCubeObj);
  const Scene scene = load_scene(dir.write("scene.json", scene_with_obstacles()));
  ASSERT_EQ(scene.obstacles.size(), 5u);
  const Obstacle& table = scene.obstacles[0];
  EXPECT_EQ(table.name, "table");
  EXPECT_EQ(table.shape, "plane");
  ASSERT_TRUE(table.plane);
  EXPECT_NEAR((table.plane->normal - Vec3::UnitZ()).norm(), 0, 1e-15);  // made unit
  EXPECT_NEAR(table.plane->point.z(), -0.1, 1e-15);
  const Obstacle& peg = scene.obstacles[1];
  EXPECT_EQ(peg.shape, "box");
  ASSERT_EQ(peg.points.size(), 8u);
  Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : peg.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Turned a quarter about z: 40 mm along x, 20 along y, around (0, 0.1, 0).
  EXPECT_NEAR((hi - lo - Vec3(0.04, 0.02, 0.06)).norm(), 0, 1e-12);
  EXPECT_NEAR(((hi + lo) / 2 - Vec3(0, 0.1, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(scene.obstacles[2].name, "obstacle 3");
  EXPECT_EQ(scene.obstacles[2].radius, 0.03);
  EXPECT_EQ(scene.obstacles[3].radius, 0.01);
  const Obstacle& fixture = scene.obstacles[4];
  EXPECT_EQ(fixture.triangles.size(), 12u);
  lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : fixture.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  EXPECT_NEAR((lo - Vec3(0, 0, 0.05)).norm(), 0, 1e-15);  // mm to m, then placed
  EXPECT_NEAR((hi - Vec3(0.01, 0.01, 0.06)).norm(), 0, 1e-15);
  EXPECT_EQ(scene.contact.distance, 0.002);
  EXPECT_EQ(scene.contact.stiffness, 50.0);
  EXPECT_EQ(scene.contact.sweep_steps, 12);
  EXPECT_FALSE(scene.contact.self);
}

TEST(ObstaclesScene, WithoutObstaclesTheSceneHasNoneAndDefaultContact) {
  test::TempDir dir;
  const Scene scene = load_scene(dir.write("scene.json", test::kClampedBarScene));
  EXPECT_TRUE(scene.obstacles.empty());
  EXPECT_EQ(scene.contact.distance, 1e-3);
  EXPECT_FALSE(scene.contact.stiffness);
  EXPECT_EQ(scene.contact.sweep_steps, 64);
}

TEST(ObstaclesScene, TheWriterKeepsObstaclesAndRebasesTheirMeshFiles) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "meshes");
  std::filesystem::create_directories(dir.path() / "out" / "deeper");
  dir.write("meshes/cube.obj", kCubeObj);
  const auto source = dir.write("scene.json", scene_with_obstacles());
  const auto out = dir.path() / "out" / "deeper" / "calibrated.json";
  const nlohmann::ordered_json j = scene_json_with_values(source, load_scene(source), out);
  EXPECT_EQ(j["obstacles"][4]["mesh"]["file"], "../../meshes/cube.obj");
  EXPECT_EQ(j["obstacles"][0]["name"], "table");
  EXPECT_EQ(j["contact"]["distance"], 0.002);
  {
    std::ofstream file(out);
    file << j.dump(2);
  }
  const Scene again = load_scene(out);
  ASSERT_EQ(again.obstacles.size(), 5u);
  EXPECT_EQ(again.obstacles[4].points, load_scene(source).obstacles[4].points);
}

}  // namespace
}  // namespace shapectl
