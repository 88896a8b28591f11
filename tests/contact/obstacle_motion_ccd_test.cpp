// CCD of the obstacles' own motion (ObstacleContact::max_obstacle_step): thin obstacles on a
// "link" that one motion carries wholly through the object, so that where they end they are
// clear of it, are stopped before they reach it, for each kind of pair (object vertex –
// obstacle face, obstacle corner – object face, obstacle segment – object edge).
#include <shapectl/contact/obstacle_contact.hpp>

#include <gtest/gtest.h>

#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

// Link 0 translated by s·v: every point travels |v| h over [s, s + h], exactly.
class Translation : public ObstacleMotion {
 public:
  explicit Translation(const Vec3& v) : v_(v) {}
  void move_to(double s) override { displacement_ = Eigen::Translation3d(s * v_); }
  const Eigen::Isometry3d& displacement(int) const override { return displacement_; }
  double time_to_travel(int, const Vec3&, double distance) const override {
    return distance / v_.norm();
  }
  double travel(int, const Vec3&, double h) const override { return v_.norm() * h; }

 private:
  Vec3 v_;
  Eigen::Isometry3d displacement_ = Eigen::Isometry3d::Identity();
};

std::vector<Eigen::Isometry3d> at(const Vec3& offset) {
  return {Eigen::Isometry3d(Eigen::Translation3d(offset))};
}

// The obstacle (on link 0) moving by v from where it is, against the object at rest.
void expect_sweep_stopped(const TetMesh& mesh, Obstacle obstacle, const Vec3& v, double start_gap) {
  obstacle.link = 0;
  const ObstacleContact contact(mesh, {obstacle}, 0.001, 1.0, at(Vec3::Zero()));
  const Positions x = mesh.rest_vector();
  ASSERT_EQ(contact.first_intersection(x)[0], -1);
  // Where the motion ends the obstacle is clear of the object: only the sweep sees it pass.
  ASSERT_EQ(contact.posed(at(v)).first_intersection(x)[0], -1);
  bool passes = false;
  for (int k = 1; k < 1000 && !passes; ++k)
    passes = contact.posed(at(k / 1000.0 * v)).first_intersection(x)[0] >= 0;
  ASSERT_TRUE(passes);  // the checks below could fail

  Translation motion(v);
  int limiting = -1;
  const double s = contact.max_obstacle_step(x, motion, &limiting);
  EXPECT_GT(s, 0);
  EXPECT_LT(s, 1);
  EXPECT_EQ(limiting, 0);
  // The gap keeps at least 10 % of where it started all the way to s, and s is not far short
  // of where it reaches that (additive CCD stops within 10 % of the way there).
  for (int k = 0; k <= 100; ++k) {
    const ContactSummary c = contact.posed(at(k / 100.0 * s * v)).summary(x);
    EXPECT_GE(c.min_distance, 0.1 * start_gap * (1 - 1e-9)) << "at " << k / 100.0 * s;
  }
  EXPECT_GT(s * v.norm(), 0.8 * 0.9 * start_gap);
}

// The object: a 0.1 × 0.1 × 0.02 box centred at the origin, bottom face at z = −0.01.
TEST(ObstacleMotionCcd, StopsAThinPlateSweptUpThroughTheObject) {
  // A plate 1 mm thick 0.8 mm under the object, lifted 5 cm: its faces meet object vertices.
  expect_sweep_stopped(make_box_mesh({0.1, 0.1, 0.02}, {4, 4, 1}),
                       make_box("plate", Vec3(0.3, 0.3, 0.001),
                                Eigen::Isometry3d(Eigen::Translation3d(0, 0, -0.0113))),
                       Vec3(0.002, 0.001, 0.05), 0.0008);
}

TEST(ObstacleMotionCcd, StopsAPinSweptThroughAFaceBetweenItsVertices) {
  // One cell: the pin's corners meet the inside of the bottom face's triangles.
  expect_sweep_stopped(make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1}),
                       make_box("pin", Vec3(0.004, 0.004, 0.001),
                                Eigen::Isometry3d(Eigen::Translation3d(0.02, -0.015, -0.0115))),
                       Vec3(0, 0, 0.05), 0.001);
}

TEST(ObstacleMotionCcd, StopsAWireSweptAcrossAnEdge) {
  // A thin capsule under the bottom face near the +x edge, skew to it, moved sideways and up
  // past that edge: it crosses the edge between its vertices.
  expect_sweep_stopped(make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1}),
                       make_capsule("wire", Vec3(0.04, -0.2, -0.0115), Vec3(0.05, 0.2, -0.0115),
                                    0.0005),
                       Vec3(0.03, 0, 0.008), 0.001);
}

TEST(ObstacleMotionCcd, IsOneForObstaclesThatStayAway) {
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1});
  Obstacle ball = make_sphere("ball", Vec3(0, 0, 0.05), 0.01);
  ball.link = 0;
  const ObstacleContact contact(mesh, {ball}, 0.001, 1.0, at(Vec3::Zero()));
  Translation motion(Vec3(0.1, 0, 0.01));  // sideways and away
  EXPECT_EQ(contact.max_obstacle_step(mesh.rest_vector(), motion), 1);
  // Not on a link: nothing moves.
  const ObstacleContact fixed(mesh, {make_sphere("ball", Vec3(0, 0, 0.011), 0.0005)}, 0.001, 1.0);
  Translation down(Vec3(0, 0, -0.1));
  EXPECT_EQ(fixed.max_obstacle_step(mesh.rest_vector(), down), 1);
}

}  // namespace
}  // namespace shapectl
