// Obstacles and contacts in the session's messages (docs/gui.md): the YuMi's bar over a peg it
// sags onto. The scene message carries the obstacles and the contact settings, each state the
// contacts at its positions; a scene without obstacles has neither.
#include <shapectl/server/session.hpp>

#include <gtest/gtest.h>

#include "support/controller_wait.hpp"
#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

// yumi_bar.json's bar (centre z 0.25527, 3 cm thick, along y) over a peg across its middle
// 0.5 mm below it, within the default 1 mm contact distance from the start.
std::string bar_over_peg() {
  nlohmann::json scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  const double z = 0.25527 - 0.015 - 0.0005 - 0.01;
  scene["obstacles"] = {
      {{"name", "peg"},
       {"capsule", {{"a", {0.33, 0.0, z}}, {"b", {0.45, 0.0, z}}, {"radius", 0.01}}}},
      {{"name", "table"}, {"plane", {{"point", {0.0, 0.0, 0.1}}, {"normal", {0.0, 0.0, 1.0}}}}}};
  return scene.dump();
}

TEST(SessionContacts, TheSceneMessageCarriesTheObstaclesAndEachStateTheContacts) {
  const test::TempDir dir;
  Session session(dir.write("bar_over_peg.json", bar_over_peg()), {});
  const auto scene = nlohmann::json::parse(session.scene_message());
  ASSERT_EQ(scene["obstacles"].size(), 2u);
  EXPECT_EQ(scene["obstacles"][0]["name"], "peg");
  EXPECT_EQ(scene["obstacles"][0]["shape"], "capsule");
  EXPECT_EQ(scene["obstacles"][0]["points"].size(), 2u);
  EXPECT_EQ(scene["obstacles"][0]["radius"], 0.01);
  EXPECT_EQ(scene["obstacles"][1]["plane"]["normal"], nlohmann::json({0.0, 0.0, 1.0}));
  EXPECT_EQ(scene["contact"]["distance"], 0.001);
  EXPECT_GT(scene["contact"]["stiffness"].get<double>(), 0);

  test::wait_until(
      session.controller(), [](const ControllerSnapshot& s) { return s.positions.size() > 0; }, 60);
  session.tick();
  const auto contacts = nlohmann::json::parse(session.state_message(1))["contacts"];
  ASSERT_TRUE(contacts.is_object()) << contacts;
  const int count = contacts["count"];
  EXPECT_GT(count, 0);
  EXPECT_EQ(contacts["by_obstacle"]["peg"]["count"], count);
  EXPECT_EQ(contacts["by_obstacle"]["table"]["count"], 0);
  EXPECT_GT(contacts["min_distance"].get<double>(), 0);
  EXPECT_LT(contacts["min_distance"].get<double>(), 0.001);
  // Every pair is listed (far fewer than the cap), and their forces add up to the total: the
  // peg pushes the bar up.
  ASSERT_EQ(contacts["points"].size(), static_cast<std::size_t>(count));
  EXPECT_EQ(contacts["points_total"], count);
  Vec3 sum = Vec3::Zero();
  for (const auto& p : contacts["points"]) sum += Vec3(p[3], p[4], p[5]);
  const Vec3 total(contacts["force_total"][0], contacts["force_total"][1],
                   contacts["force_total"][2]);
  EXPECT_GT(total.z(), 0);
  EXPECT_LT((sum - total).norm(), 1e-9 * total.norm())
      << sum.transpose() << " vs " << total.transpose();
}

// yumi_bar.json with the bar slit through its middle (tests/data/slit_bar.py), its upper slab's
// middle pressed down onto the lower one, and contact.self.
std::string slit_bar_pressed() {
  nlohmann::json scene = nlohmann::json::parse(test::bundled_scene_text("yumi_bar.json"));
  scene["object"]["mesh"] = {{"file", test::source_path("tests/data/slit_bar.node").string()}};
  scene["loads"] = {{{"box", {{"min", {-0.021, -1, 0.0005}}, {"max", {0.021, 1, 0.0076}}}},
                     {"force", {0, 0, -0.5}}}};
  scene["contact"] = {{"self", true}};
  return scene.dump();
}

TEST(SessionContacts, SelfContactWithoutObstaclesHasItsOwnPart) {
  const test::TempDir dir;
  Session session(dir.write("slit_bar.json", slit_bar_pressed()), {});
  const auto scene = nlohmann::json::parse(session.scene_message());
  EXPECT_EQ(scene["obstacles"], nlohmann::json::array());
  EXPECT_EQ(scene["contact"]["distance"], 0.001);
  EXPECT_EQ(scene["contact"]["self"], true);
  test::wait_until(
      session.controller(), [](const ControllerSnapshot& s) { return s.positions.size() > 0; }, 60);
  session.tick();
  const auto contacts = nlohmann::json::parse(session.state_message(1))["contacts"];
  ASSERT_TRUE(contacts.is_object()) << contacts;
  EXPECT_EQ(contacts["count"], 0);
  const auto& self = contacts["self"];
  const int count = self["count"];
  EXPECT_GT(count, 0);
  EXPECT_GT(self["min_distance"].get<double>(), 0);
  EXPECT_LT(self["min_distance"].get<double>(), 0.001);
  ASSERT_EQ(self["points"].size(), static_cast<std::size_t>(count));
  // Each point in the slit, in the bar's middle: the bar is along y at x 0.39047, z 0.25527
  // (yumi_bar.json), the slit 2 mm high, its upper slab pressed down by ~1.5 mm there.
  for (const auto& p : self["points"]) {
    EXPECT_NEAR(p[0].get<double>(), 0.39047, 0.016) << p;
    EXPECT_LT(std::abs(p[1].get<double>()), 0.12) << p;
    EXPECT_NEAR(p[2].get<double>(), 0.25527, 0.01) << p;
  }
}

TEST(SessionContacts, WithoutObstaclesThereAreNoContacts) {
  Session session(test::source_path("scenes/yumi_bar.json"), {});
  const auto scene = nlohmann::json::parse(session.scene_message());
  EXPECT_EQ(scene["obstacles"], nlohmann::json::array());
  EXPECT_TRUE(scene["contact"].is_null());
  session.tick();
  EXPECT_FALSE(nlohmann::json::parse(session.state_message(1)).contains("contacts"));
}

}  // namespace
}  // namespace shapectl::server
