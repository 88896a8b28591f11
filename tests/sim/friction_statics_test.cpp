// Statics with Coulomb friction (issue 34): a block on a plane tilted by α stays where it lands
// when μ > tan α, and is reported as sliding (never converged) when μ < tan α; a robot dragging
// a bar along a table is held back.
#include <shapectl/sim/object_statics.hpp>

#include <gtest/gtest.h>

#include <cmath>

#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/scene_checks.hpp>

#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

constexpr double kTilt = 20 * M_PI / 180;  // tan α = 0.364

// The plane through the origin with its normal turned by α about y; a 100 × 60 × 40 mm block
// turned with it, its bottom face 0.5 mm above the plane; gravity straight down.
Eigen::Matrix3d tilt() { return Eigen::AngleAxisd(kTilt, Vec3::UnitY()).toRotationMatrix(); }

Scene block_on_slope(double friction) {
  Scene s;
  s.source = "block_on_slope";
  const Vec3 size(0.1, 0.06, 0.04);
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh(size, {5, 3, 2}));
  s.material = material_from_youngs(1e6, 0.3, 500);
  s.T_world_object.linear() = tilt();
  s.T_world_object.translation() = tilt() * Vec3(0, 0, size.z() / 2 + 0.5e-3);
  s.statics.relative_tolerance = 1e-10;
  s.contact.distance = 1e-3;
  s.contact.friction = friction;
  s.obstacles.push_back(make_plane("slope", Vec3::Zero(), tilt() * Vec3::UnitZ()));
  check_scene(s);
  return s;
}

// The largest motion along the slope, from x0 to x, of the nodes within `height` of it at x.
double largest_tangential_motion(const Positions& x0, const Positions& x,
                                 double height = INFINITY) {
  const Vec3 n = tilt() * Vec3::UnitZ();
  double m = 0;
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) {
    if (x.segment<3>(3 * i).dot(n) >= height) continue;
    const Vec3 d = x.segment<3>(3 * i) - x0.segment<3>(3 * i);
    m = std::max(m, (d - d.dot(n) * n).norm());
  }
  return m;
}

TEST(FrictionStatics, ABlockStaysOnASlopeSteeperThanNothingButGentlerThanItsFriction) {
  const Scene scene = block_on_slope(0.5);
  const ObjectStatics statics(scene);
  ASSERT_GT(statics.friction().coefficient, 0);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  ASSERT_TRUE(r.converged()) << r.reason;
  EXPECT_NE(r.reason.find("friction settled"), std::string::npos) << r.reason;
  // Nothing slid: the nodes touching the slope moved along it by less than the mollifier's slip
  // ε (14 µm here); every node by less than 0.1 mm (that, the elastic shear and the block's tilt
  // on the barrier's compliance).
  const Positions start = scene.world_rest_positions();
  const double moved = largest_tangential_motion(start, x);
  const double slipped = largest_tangential_motion(start, x, scene.contact.distance);
  std::cout << "mu 0.5 on 20 deg: largest motion along the slope " << moved
            << " m, of the contact nodes " << slipped << " m, slip length "
            << statics.friction().slip << " m, " << r.iterations << " Newton iterations\n";
  EXPECT_LT(moved, 1e-4);
  EXPECT_LT(slipped, statics.friction().slip);
  const ContactSummary contacts = statics.contact()->summary(x);
  EXPECT_GT(contacts.count, 0);
  // The slope's normal push carries the weight's normal part, cos α W; friction the rest.
  EXPECT_NEAR(contacts.force_total.dot(tilt() * Vec3::UnitZ()), std::cos(kTilt) * statics.weight(),
              1e-6 * statics.weight());
}

TEST(FrictionStatics, ABlockOnASlopeSteeperThanItsFrictionSlidesAndSaysSo) {
  const Scene scene = block_on_slope(0.2);
  const ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_FALSE(r.converged()) << r.reason;
  EXPECT_EQ(r.status, StaticsStatus::NotConverged);
  EXPECT_NE(r.reason.find("slides along obstacle 'slope'"), std::string::npos) << r.reason;
  std::cout << r.reason << "\n";
}

TEST(FrictionStatics, JustAboveTanAlphaHoldsJustBelowSlides) {
  for (const double mu : {std::tan(kTilt) * 1.05, std::tan(kTilt) * 0.95}) {
    const Scene scene = block_on_slope(mu);
    const ObjectStatics statics(scene);
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    EXPECT_EQ(r.converged(), mu > std::tan(kTilt)) << "mu " << mu << ": " << r.reason;
  }
}

TEST(FrictionStatics, FrictionlessSceneHasNoFrictionSolve) {
  const Scene scene = block_on_slope(0);
  const ObjectStatics statics(scene);
  EXPECT_EQ(statics.friction().coefficient, 0);
  EXPECT_EQ(statics.terms().size(), 3u);  // elasticity, gravity, contact: as before
}

// The robot's path: each solve anchors the friction at its warm start, the previous equilibrium.
// Two arms hold a foam bar whose middle sags onto a table 0.5 mm under it; both swing about z by
// 0.01 rad, carrying the bar ~4 mm along its axis. The lagged friction settles on this path
// too, and holds the middle back: less than without friction, though only by about μλ over the
// bar's axial stiffness (the light foam bar's ~0.1 N on the table against ~250 N/m: ~0.3 µm).
struct Swing {
  double middle_motion = 0;  // largest motion along the table of a node touching it, m
  StaticsResult result;
};
Swing swing_over_table(double friction) {
  Scene scene = test::two_arm_scene({12, 2, 2});
  const Positions rest = scene.world_rest_positions();
  const double table = test::add_table_under(scene, 0.5e-3);
  scene.contact.distance = 1e-3;
  scene.contact.friction = friction;
  scene.statics.max_iterations = 300;
  const GrippedObject object(scene);
  const ObjectState before = object.solve_from(object.reference_joints(), rest);
  EXPECT_TRUE(before.statics().converged()) << before.statics().reason;
  Eigen::VectorXd joints = object.reference_joints();
  joints[0] += 0.01;
  joints[3] += 0.01;
  Positions x = before.positions();
  object.carry_gripped_nodes(before.joints(), joints, before.positions(), x);
  const ObjectState after = object.solve_from(joints, x, 0, &before);
  Swing s{0, after.statics()};
  for (Eigen::Index i = 0; i < rest.size() / 3; ++i)
    if (before.positions()[3 * i + 2] < table + scene.contact.distance)
      s.middle_motion = std::max(s.middle_motion,
                                 (after.positions() - before.positions()).segment<2>(3 * i).norm());
  return s;
}

TEST(FrictionStatics, ARobotDraggingABarAlongATableIsHeldBackByFriction) {
  const Swing free = swing_over_table(0), held = swing_over_table(1.0);
  ASSERT_TRUE(free.result.converged()) << free.result.reason;
  ASSERT_TRUE(held.result.converged()) << held.result.reason;
  EXPECT_NE(held.result.reason.find("friction settled"), std::string::npos) << held.result.reason;
  std::cout << "middle moved " << free.middle_motion << " m frictionless, " << held.middle_motion
            << " m with friction 1\n";
  EXPECT_GT(free.middle_motion, 3e-3);
  EXPECT_LT(held.middle_motion, free.middle_motion);
}

}  // namespace
}  // namespace shapectl
