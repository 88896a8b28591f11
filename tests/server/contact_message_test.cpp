// The obstacles and contacts as the GUI's messages carry them (docs/gui.md): every field, the
// capped point list keeping the closest pairs, null for a min gap that does not exist.
#include <shapectl/server/contact_message.hpp>

#include <gtest/gtest.h>

#include <limits>

namespace shapectl::server {
namespace {

std::vector<Obstacle> table_and_peg() {
  return {make_plane("table", Vec3(0, 0, 0.1), Vec3::UnitZ()),
          make_capsule("peg", Vec3(0.4, 0, 0.1), Vec3(0.4, 0, 0.2), 0.01)};
}

TEST(ContactMessage, ObstaclesCarryTheirGeometryInTheWorld) {
  const nlohmann::json j = obstacles_json(table_and_peg());
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["name"], "table");
  EXPECT_EQ(j[0]["shape"], "plane");
  EXPECT_EQ(j[0]["plane"]["point"], nlohmann::json({0.0, 0.0, 0.1}));
  EXPECT_EQ(j[0]["plane"]["normal"], nlohmann::json({0.0, 0.0, 1.0}));
  EXPECT_TRUE(j[0]["points"].empty());
  EXPECT_EQ(j[1]["shape"], "capsule");
  EXPECT_TRUE(j[1]["plane"].is_null());
  EXPECT_EQ(j[1]["points"], nlohmann::json({{0.4, 0.0, 0.1}, {0.4, 0.0, 0.2}}));
  EXPECT_EQ(j[1]["edges"], nlohmann::json({{0, 1}}));
  EXPECT_TRUE(j[1]["triangles"].empty());
  EXPECT_EQ(j[1]["radius"], 0.01);
}

TEST(ContactMessage, ContactsSumUpPerObstacleAndKeepTheClosestPointsWhenCapped) {
  ContactSummary s;
  s.count = 3;
  s.min_distance = 1e-4;
  s.force_total = Vec3(0, 0, 0.3);
  s.by_obstacle = {{.count = 2, .force = Vec3(0, 0, 0.25)},
                   {.count = 1, .force = Vec3(0, 0, 0.05)}};
  s.points = {{.obstacle = 0, .point = Vec3(1, 2, 3), .force = Vec3(0, 0, 0.05), .distance = 5e-4},
              {.obstacle = 0, .point = Vec3(4, 5, 6), .force = Vec3(0, 0, 0.2), .distance = 1e-4},
              {.obstacle = 1, .point = Vec3(7, 8, 9), .force = Vec3(0, 0, 0.05), .distance = 3e-4}};
  const nlohmann::json all = contacts_json(s, table_and_peg());
  EXPECT_EQ(all["count"], 3);
  EXPECT_EQ(all["min_distance"], 1e-4);
  EXPECT_EQ(all["force_total"], nlohmann::json({0.0, 0.0, 0.3}));
  EXPECT_EQ(all["by_obstacle"]["table"]["count"], 2);
  EXPECT_EQ(all["by_obstacle"]["table"]["force"], nlohmann::json({0.0, 0.0, 0.25}));
  EXPECT_EQ(all["by_obstacle"]["peg"]["count"], 1);
  EXPECT_EQ(all["points_total"], 3);
  ASSERT_EQ(all["points"].size(), 3u);
  EXPECT_EQ(all["points"][0], nlohmann::json({4.0, 5.0, 6.0, 0.0, 0.0, 0.2}));  // closest first

  const nlohmann::json capped = contacts_json(s, table_and_peg(), 2);
  EXPECT_EQ(capped["count"], 3);
  EXPECT_EQ(capped["points_total"], 3);
  ASSERT_EQ(capped["points"].size(), 2u);
  EXPECT_EQ(capped["points"][0][0], 4.0);
  EXPECT_EQ(capped["points"][1][0], 7.0);  // the farthest pair (5e-4) is the one left out
}

TEST(ContactMessage, NoPairWithinTheDistanceHasANullMinimumGap) {
  ContactSummary s;
  s.min_distance = std::numeric_limits<double>::infinity();
  s.by_obstacle.resize(2);
  const nlohmann::json j = contacts_json(s, table_and_peg());
  EXPECT_EQ(j["count"], 0);
  EXPECT_TRUE(j["min_distance"].is_null());
  EXPECT_TRUE(j["points"].empty());
  EXPECT_EQ(j["by_obstacle"]["peg"]["count"], 0);
  EXPECT_NO_THROW((void)j.dump());  // no infinity reaches the JSON text
}

TEST(ContactMessage, SelfContactHasItsCountGapAndPointsClosestFirst) {
  ContactSummary none;
  none.min_distance = std::numeric_limits<double>::infinity();
  SelfContactSummary self;
  self.count = 3;
  self.min_distance = 2e-4;
  self.points = {Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(7, 8, 9)};
  self.distances = {6e-4, 2e-4, 4e-4};
  const nlohmann::json j = contacts_json(none, {}, 2, &self);
  EXPECT_EQ(j["count"], 0);  // the obstacles' part: none
  EXPECT_TRUE(j["by_obstacle"].empty());
  EXPECT_EQ(j["self"]["count"], 3);
  EXPECT_EQ(j["self"]["min_distance"], 2e-4);
  EXPECT_EQ(j["self"]["points_total"], 3);
  EXPECT_EQ(j["self"]["points"], nlohmann::json({{4.0, 5.0, 6.0}, {7.0, 8.0, 9.0}}));
  // None touching: a null gap, no points; without self-contact no "self" at all.
  const SelfContactSummary untouched;
  const nlohmann::json open = contacts_json(none, {}, 2, &untouched);
  EXPECT_EQ(open["self"]["count"], 0);
  EXPECT_TRUE(open["self"]["min_distance"].is_null());
  EXPECT_TRUE(open["self"]["points"].empty());
  EXPECT_FALSE(contacts_json(none, {}).contains("self"));
}

}  // namespace
}  // namespace shapectl::server
