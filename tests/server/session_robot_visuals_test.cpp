// What the session sends for drawing the robot: the visuals' URDF colours in the scene message,
// and with a link the link poses at the measured joints (the page's ghost robot) in each state.
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
