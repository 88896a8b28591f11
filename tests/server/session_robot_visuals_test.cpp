// What the session sends for drawing the robot: the visuals' URDF colours in the scene message,
// its mesh visuals' URLs and the table of files behind them, and with a link the link poses at
// the measured joints (the page's ghost robot) in each state.
#include <gtest/gtest.h>

#include <thread>

#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/session.hpp>

#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

TEST(SessionRobotVisuals, VisualsCarryTheirUrdfColourOrNull) {
  const auto scene_file = test::source_path("scenes/yumi_bar.json");
  const Scene scene = load_scene(scene_file);
  Session session(scene_file, find_bundled_scenes(test::source_path("scenes")));
  const auto links = nlohmann::json::parse(session.scene_message())["robot"]["links"];
  int coloured = 0;
  for (std::size_t l = 0; l < links.size(); ++l)
    for (std::size_t v = 0; v < links[l]["visuals"].size(); ++v) {
      const auto& shape = scene.robot->model->links()[l].visual_shapes[v];
      const auto& color = links[l]["visuals"][v]["color"];
      ASSERT_EQ(color.is_null(), !shape.rgba.has_value());
      if (color.is_null()) continue;
      ++coloured;
      for (int i = 0; i < 4; ++i) EXPECT_EQ(color[i].get<double>(), (*shape.rgba)[i]);
    }
  EXPECT_GT(coloured, 10) << "the YuMi's materials";
  EXPECT_TRUE(nlohmann::json::parse(session.state_message(1))["measured_links"].is_null())
      << "no link, no measured robot";
}

TEST(SessionRobotVisuals, MeshVisualsGetAUrlIntoATableOfTheFilesTheUrdfNames) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "share" / "bot" / "meshes");
  const auto stl = dir.write("share/bot/meshes/arm.stl", "solid a\nendsolid a\n");
  dir.write("bot.urdf",
            "<robot name='bot'><link name='base'/><joint name='j' type='revolute'>"
            "<parent link='base'/><child link='arm'/><origin xyz='0 0 0.2'/><axis xyz='0 0 1'/>"
            "<limit lower='-1' upper='1' velocity='1' effort='1'/></joint><link name='arm'>"
            "<visual><geometry><mesh filename='package://bot/meshes/arm.stl' scale='2 2 2'/>"
            "</geometry></visual><visual><geometry><mesh filename='package://bot/meshes/no.dae'/>"
            "</geometry></visual></link></robot>");
  const auto scene_file =
      dir.write("scene.json",
                R"({"object": {"mesh": {"box": {"size": [0.1, 0.02, 0.02], "cells": [5, 2, 2]}},
          "material": {"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40},
          "pose": {"position": [0.3, 0, 0.2], "rpy": [0, 0, 0]}},
          "robot": {"urdf": "bot.urdf", "end_effectors": [{"name": "tool", "link": "arm", "tcp": [0.25, 0, 0]}]},
          "grips": [{"end_effector": "tool", "region": {"box": {"min": [-0.051, -0.011, -0.011], "max": [-0.049, 0.011, 0.011]}}}]})");
  Session session(scene_file, {}, nullptr, {}, {}, {dir.path() / "share"});
  const auto message = nlohmann::json::parse(session.scene_message());
  const auto& visuals = message["robot"]["links"][1]["visuals"];
  ASSERT_EQ(visuals.size(), 2u);
  EXPECT_EQ(visuals[0]["kind"], "mesh");
  EXPECT_EQ(visuals[0]["url"], "/robot-mesh/0.stl");
  EXPECT_EQ(visuals[0]["format"], "stl");
  EXPECT_EQ(visuals[0]["scale"], nlohmann::json({2.0, 2.0, 2.0}));
  EXPECT_TRUE(visuals[1]["url"].is_null());
  ASSERT_EQ(message["warnings"].size(), 1u);
  EXPECT_NE(message["warnings"][0].get<std::string>().find(
                "link 'arm': visual mesh "
                "'package://bot/meshes/no.dae' not found"),
            std::string::npos);

  EXPECT_EQ(session.robot_mesh_file(0, "stl"), std::filesystem::absolute(stl));
  EXPECT_FALSE(session.robot_mesh_file(0, "obj")) << "another extension";
  EXPECT_FALSE(session.robot_mesh_file(1, "dae")) << "not found";
  EXPECT_FALSE(session.robot_mesh_file(2, "stl")) << "past the table";
}

TEST(SessionRobotVisuals, MeasuredLinksAreTheLinkPosesAtTheMeasuredJoints) {
  const auto scene_file = test::source_path("scenes/yumi_bar.json");
  const Scene scene = load_scene(scene_file);
  LinkConfig config;
  config.kind = LinkKind::Sim;
  // The real robot elsewhere than the optimizer's joints, so the two poses differ.
  config.sim_initial_joints = scene.robot->reference_joints.array() + 0.1;
  auto link = make_robot_link(config, *scene.robot->model, scene.robot->collisions);
  link->start();
  Session session(scene_file, find_bundled_scenes(test::source_path("scenes")), link.get());
  nlohmann::json state;
  for (int k = 0; k < 600; ++k) {  // up to 30 s at 20 ms: the link's first feedback
    state = nlohmann::json::parse(session.state_message(1));
    if (!state["measured_links"].is_null()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  link->stop();
  ASSERT_FALSE(state["measured_links"].is_null()) << state["link"].dump();
  const auto measured = state["link"]["measured"].get<std::vector<double>>();
  const KinematicsState fk =
      forward_kinematics(*scene.robot->model,
                         Eigen::Map<const Eigen::VectorXd>(measured.data(), measured.size()));
  ASSERT_EQ(state["measured_links"].size(), fk.T_world_link.size());
  double moved = 0;
  for (std::size_t l = 0; l < fk.T_world_link.size(); ++l) {
    const Eigen::Matrix4d& T = fk.T_world_link[l].matrix();
    for (int i = 0; i < 16; ++i) {
      EXPECT_NEAR(state["measured_links"][l][i].get<double>(), T.data()[i], 1e-12);
      moved = std::max(moved, std::abs(state["measured_links"][l][i].get<double>() -
                                       state["links"][l][i].get<double>()));
    }
  }
  EXPECT_GT(moved, 0.01) << "measured, not the optimizer's joints";
}

}  // namespace
}  // namespace shapectl::server
