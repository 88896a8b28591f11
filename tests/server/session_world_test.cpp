// `serve --robot sim --world WORLD.json`: the session settles the simulated world at the sim
// robot's measured joints, observes the target nodes and the state carries the true error.
#include <gtest/gtest.h>

#include <thread>

#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/session.hpp>

#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

TEST(SessionWorld, TheWorldIsObservedAtTheRobotsMeasuredJointsAndItsTrueErrorIsShown) {
  const auto scene_file = test::source_path("scenes/yumi_bar.json");
  const Scene model = load_scene(scene_file);
  Scene truth = model;
  truth.grips[0].offset.translation() = Vec3(0, 0.004, 0);
  LinkConfig config;
  config.kind = LinkKind::Sim;
  config.sim_initial_joints = model.robot->reference_joints;
  auto link = make_robot_link(config, *model.robot->model, model.robot->collisions);
  link->start();
  Session session(scene_file, find_bundled_scenes(test::source_path("scenes")), link.get());
  session.set_world(std::make_unique<SimulatedWorld>(truth, model, SimulatedCamera{}, 10.0));
  EXPECT_EQ(nlohmann::json::parse(session.scene_message())["scenes"].size(), 1u)
      << "no switching away from the world";

  const auto first = session.controller().snapshot();
  const Vec3 p = first->positions.segment<3>(3 * 7);
  ASSERT_TRUE(session.handle(R"({"type":"set_feedback","on":true})").ok);
  ASSERT_TRUE(session
                  .handle(nlohmann::json{{"type", "set_target"},
                                         {"node", 7},
                                         {"position", {p.x(), p.y(), p.z() + 0.01}}}
                              .dump())
                  .ok);
  nlohmann::json state;
  for (int k = 0; k < 600; ++k) {  // up to 30 s at 20 ms: the link's feedback must arrive first
    session.tick();
    state = nlohmann::json::parse(session.state_message(1));
    if (state["observations"].get<int>() >= 3 && state["true_error"].is_number()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  link->stop();
  ASSERT_GE(state["observations"].get<int>(), 3) << state.dump();
  EXPECT_TRUE(state["true_error"].is_number());
  // The world's grip is 4 mm off: its node 7 is observed off the model's, and the page sees it.
  EXPECT_GT(state["model_error"].get<double>(), 1e-3);
  ASSERT_EQ(state["observed_markers"].size(), 1u);
  EXPECT_EQ(state["observed_markers"][0][0], 7);
}

TEST(SessionWorld, AWorldNeedsALink) {
  const auto scene_file = test::source_path("scenes/yumi_bar.json");
  const Scene model = load_scene(scene_file);
  Session session(scene_file, find_bundled_scenes(test::source_path("scenes")));
  EXPECT_THROW(session.set_world(
                   std::make_unique<SimulatedWorld>(model, model, SimulatedCamera{}, 10.0)),
               InputError);
}

}  // namespace
}  // namespace shapectl::server
