// URDF mesh visuals on the command line: every command that loads a robot takes --package-path,
// and one that cannot find a mesh says which URDF, link and file; collision meshes are ignored for
// the collision model with one line, not one per mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

// base holds the far end of the bar; arm (revolute about z) its near end with its tool. arm's
// visual is an STL in the package mesh_bot; two collision meshes.
const char* const kUrdf = R"(<?xml version="1.0"?>
<robot name="mesh_bot">
  <link name="base">
    <collision><geometry><mesh filename="package://mesh_bot/meshes/base_hull.stl"/></geometry></collision>
  </link>
  <joint name="swing" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="10"/>
  </joint>
  <link name="arm">
    <visual><geometry><mesh filename="package://mesh_bot/meshes/arm.stl"/></geometry></visual>
    <collision><geometry><mesh filename="package://mesh_bot/meshes/arm_hull.stl"/></geometry></collision>
  </link>
</robot>
)";

const char* const kScene = R"({
  "object": {"mesh": {"box": {"size": [0.1, 0.02, 0.02], "cells": [5, 2, 2]}},
             "material": {"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40},
             "pose": {"position": [0.3, 0, 0.2], "rpy": [0, 0, 0]}},
  "gravity": [0, 0, -9.81],
  "robot": {"urdf": "robot/mesh_bot.urdf",
            "end_effectors": [{"name": "tool", "link": "arm", "tcp": [0.25, 0, 0]},
                              {"name": "holder", "link": "base", "tcp": [0.35, 0, 0.2]}]},
  "grips": [
    {"end_effector": "tool", "region": {"box": {"min": [-0.051, -0.011, -0.011], "max": [-0.049, 0.011, 0.011]}}},
    {"end_effector": "holder", "region": {"box": {"min": [0.049, -0.011, -0.011], "max": [0.051, 0.011, 0.011]}}}]
})";

struct MeshBot {
  TempDir dir;
  std::filesystem::path urdf, scene, share;
  MeshBot() {
    std::filesystem::create_directories(dir.path() / "robot");
    std::filesystem::create_directories(dir.path() / "share" / "mesh_bot" / "meshes");
    urdf = dir.write("robot/mesh_bot.urdf", kUrdf);
    scene = dir.write("scene.json", kScene);
    share = dir.path() / "share";
    dir.write("share/mesh_bot/meshes/arm.stl",
              "solid arm\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\n"
              "vertex 0 0.1 0\nendloop\nendfacet\nendsolid arm\n");
  }
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(RobotMeshCli, StaticsNamesTheUrdfLinkAndFileOfAMeshItCannotFind) {
  MeshBot bot;
  const auto out = bot.dir.path() / "result.json";
  const auto run = run_cli({"statics", bot.scene.string(), "--out", out.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("warning: " + bot.urdf.string() +
                         ": link 'arm': visual mesh 'package://mesh_bot/meshes/arm.stl' not found "
                         "in any package path (give --package-path"),
            std::string::npos)
      << run.err;
  // Both collision meshes in one line.
  EXPECT_EQ(count(run.err, "collision meshes ignored"), 1u) << run.err;
  EXPECT_NE(run.err.find("2 collision meshes ignored for the collision model"), std::string::npos);
}

TEST(RobotMeshCli, WithThePackagePathTheMeshIsFoundAndNothingIsSaid) {
  MeshBot bot;
  const auto out = bot.dir.path() / "result.json";
  const auto run = run_cli(
      {"statics", bot.scene.string(), "--out", out.string(), "--package-path", bot.share.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("visual mesh"), std::string::npos) << run.err;
  // The package folder itself works too (ROS convention).
  const auto itself = run_cli({"kinematics", bot.urdf.string(), "--out", out.string(),
                               "--package-path", (bot.share / "mesh_bot").string()});
  ASSERT_EQ(itself.exit_code, 0) << itself.err;
  EXPECT_EQ(itself.err.find("visual mesh"), std::string::npos) << itself.err;
}

TEST(RobotMeshCli, AMeshOfAnotherFormatIsNamed) {
  MeshBot bot;
  std::string urdf = kUrdf;
  urdf.replace(urdf.find("arm.stl"), 7, "arm.ply");
  bot.dir.write("robot/mesh_bot.urdf", urdf);
  bot.dir.write("share/mesh_bot/meshes/arm.ply", "ply\n");
  const auto out = bot.dir.path() / "result.json";
  const auto run = run_cli({"kinematics", bot.urdf.string(), "--out", out.string(),
                            "--package-path", bot.share.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("link 'arm': visual mesh 'package://mesh_bot/meshes/arm.ply' is not "
                         "STL, DAE or OBJ"),
            std::string::npos)
      << run.err;
}

TEST(RobotMeshCli, EveryCommandThatLoadsARobotTakesThePackagePath) {
  for (const std::string command :
       {"kinematics", "statics", "solve", "run", "serve", "calibrate", "author", "bench"}) {
    const auto run = run_cli({command, "--help"});
    EXPECT_EQ(run.exit_code, 0) << command;
    EXPECT_NE(run.out.find("--package-path"), std::string::npos) << command << ":\n" << run.out;
  }
}

}  // namespace
}  // namespace shapectl
