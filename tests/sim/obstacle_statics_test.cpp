// Statics with obstacles (issue 34): an object resting on a table, a propped cantilever against
// Euler–Bernoulli, and the failures that must stay honest.
#include <shapectl/sim/object_statics.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <vector>

#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/scene_checks.hpp>

namespace shapectl {
namespace {

constexpr double kTable = 0.2;  // m, the table's height

// A 100 × 60 × 40 mm block whose bottom face is `gap` above a table at z = kTable, in a tray of
// four frictionless walls `gap` from its sides: frictionless, the table alone would leave it
// free to slide and turn (a singular Hessian); the walls push only sideways, so the table
// carries the whole weight.
Scene block_on_table(double gap, bool walls) {
  Scene s;
  s.source = "block_on_table";
  const Vec3 size(0.1, 0.06, 0.04);
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh(size, {5, 3, 2}));
  s.material = material_from_youngs(1e5, 0.3, 500);
  s.T_world_object.translation() = Vec3(0.01, -0.02, kTable + size.z() / 2 + gap);
  s.statics.relative_tolerance = 1e-10;
  s.contact.distance = 1e-3;
  s.obstacles.push_back(make_plane("table", Vec3(0, 0, kTable), Vec3::UnitZ()));
  if (walls) {
    const Vec3 c = s.T_world_object.translation();
    for (int axis = 0; axis < 2; ++axis)
      for (int side : {-1, 1}) {
        Vec3 normal = Vec3::Zero();
        normal[axis] = -side;
        Vec3 point = c;
        point[axis] += side * (size[axis] / 2 + gap);
        s.obstacles.push_back(
            make_plane("wall " + std::to_string(s.obstacles.size()), point, normal));
      }
  }
  return s;
}

TEST(ObstacleStatics, NoObstaclesNoContactTerm) {
  Scene scene = block_on_table(1e-4, false);
  scene.obstacles.clear();
  scene.fixed = NodeSelection{.nodes = {0, 1, 2}};
  const ObjectStatics statics(scene);
  EXPECT_EQ(statics.contact(), nullptr);
  EXPECT_EQ(statics.terms().size(), 2u);  // elasticity and gravity only: as fast as before
  Scene with = block_on_table(1e-4, false);
  const ObjectStatics contact(with);
  ASSERT_NE(contact.contact(), nullptr);
  EXPECT_EQ(contact.terms().size(), 3u);
  EXPECT_EQ(contact.contact()->distance(), 1e-3);
  EXPECT_GT(contact.contact()->stiffness(), 0);
}

TEST(ObstacleStatics, BlockRestsOnTheTableWhichCarriesItsWeight) {
  const Scene scene = block_on_table(0.5e-3, true);
  EXPECT_NO_THROW(check_scene(scene));
  const ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  ASSERT_TRUE(r.converged()) << r.reason;
  const ContactSummary summary = statics.contact()->summary(x);
  const Vec3 weight(0, 0, statics.weight());
  // The table's push balances the weight; the walls push sideways, and cancel.
  EXPECT_NEAR(summary.by_obstacle[0].force.z(), weight.z(), 1e-6 * weight.z());
  EXPECT_LT((summary.force_total - weight).norm(), 1e-6 * weight.norm())
      << summary.force_total.transpose();
  for (int k = 1; k < 5; ++k) EXPECT_NEAR(summary.by_obstacle[k].force.z(), 0, 1e-12);
  EXPECT_GT(summary.by_obstacle[0].count, 0);
  // Every node at or above the table, the closest within the barrier's reach.
  double lowest = INFINITY;
  for (int i = 0; i < statics.mesh().node_count(); ++i) lowest = std::min(lowest, x[3 * i + 2]);
  EXPECT_GT(lowest, kTable);
  EXPECT_GT(summary.min_distance, 0);
  EXPECT_LE(summary.min_distance, scene.contact.distance);
}

TEST(ObstacleStatics, ABlockWithNothingUnderItFailsInsteadOfFalling) {
  // Obstacles present, so it is not refused as unheld up front; far above the table it has
  // nothing to rest on, and Newton must end, not converge.
  Scene scene = block_on_table(0.5, false);
  const ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x, 30);
  EXPECT_FALSE(r.converged()) << r.reason;
  EXPECT_LE(r.iterations, 30);
  for (int i = 0; i < statics.mesh().node_count(); ++i) ASSERT_GT(x[3 * i + 2], kTable);
}

TEST(ObstacleStatics, AStartThroughAnObstacleIsReportedNamingIt) {
  const Scene scene = block_on_table(0.5e-3, false);
  const ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  for (int i = 0; i < statics.mesh().node_count(); ++i) x[3 * i + 2] -= 0.01;  // 9.5 mm into it
  const StaticsResult r = statics.solve(x);
  EXPECT_EQ(r.status, StaticsStatus::Inverted);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_NE(r.reason.find("obstacle 'table'"), std::string::npos) << r.reason;
}

// check_scene's message, or "" when it accepts the scene.
std::string scene_check_error(const Scene& scene) {
  try {
    check_scene(scene);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ObstacleStatics, ARestShapeThroughAnObstacleIsRefusedByTheSceneChecks) {
  Scene scene = block_on_table(0.5e-3, false);
  // Wholly inside the block: no surfaces meet.
  scene.obstacles.push_back(make_sphere("ball", scene.T_world_object.translation(), 0.01));
  std::string what = scene_check_error(scene);
  EXPECT_NE(what.find("obstacles[1] ('ball')"), std::string::npos) << what;
  EXPECT_NE(what.find("wholly inside"), std::string::npos) << what;
  // Through the surface: the first surface triangle is named.
  scene.obstacles.back() = make_sphere("ball", scene.T_world_object.translation(), 0.025);
  what = scene_check_error(scene);
  EXPECT_NE(what.find("obstacles[1] ('ball')"), std::string::npos) << what;
  EXPECT_NE(what.find("surface triangle"), std::string::npos) << what;
  // The object inside a box.
  scene.obstacles.back() =
      make_box("crate", Vec3(1, 1, 0.1),
               Eigen::Isometry3d(Eigen::Translation3d(scene.T_world_object.translation())));
  EXPECT_THROW(check_scene(scene), std::exception);
  Scene touching = block_on_table(0, false);  // gap 0: the barrier is infinite there
  EXPECT_THROW(check_scene(touching), std::exception);
}

// A cantilever clamped at x = 0 whose free end rests on a capsule across it at x = L: under its
// own weight (uniform q) the support carries 3/8 qL (Euler–Bernoulli, propped cantilever).
constexpr double kLength = 0.5, kThickness = 0.02;

struct Propped {
  double reaction = 0;  // N, upward
  double weight = 0;    // qL
};

Propped propped_cantilever(const std::array<int, 3>& cells) {
  Scene s;
  s.source = "propped_cantilever";
  s.object_mesh =
      std::make_shared<const TetMesh>(make_box_mesh({kLength, kThickness, kThickness}, cells));
  s.T_world_object.translation() = Vec3(kLength / 2, 0, 0);
  // Slender (L/t = 25: shear deflection ~0.2 % of bending) and stiff enough for linear theory
  // (the unsupported tip would sag ~1 % of L).
  s.material = material_from_youngs(5e8, 0.05, 1000);
  s.fixed = NodeSelection{.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-kLength / 2 + 1e-6, 1, 1)}};
  s.statics.relative_tolerance = 1e-9;
  // d̂ and the rest gap tiny beside the sag (4.6 mm): the support is where the beam's end is.
  s.contact.distance = 1e-6;
  // κ so that the support's few nodes (~0.15 N each) rest near d̂/2, as the default κ puts a
  // node of mean weight: with it they would sit at ~d̂/100.
  s.contact.stiffness = 1e5;
  const double radius = 0.005;
  const double top = -kThickness / 2 - 0.5e-6;
  s.obstacles.push_back(make_capsule("support", Vec3(kLength, -0.05, top - radius),
                                     Vec3(kLength, 0.05, top - radius), radius));
  check_scene(s);
  const ObjectStatics statics(s);
  Positions x = s.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_TRUE(r.converged()) << r.reason;
  return {statics.contact()->summary(x).by_obstacle[0].force.z(), statics.weight()};
}

TEST(ObstacleStatics, ProppedCantileverReactionApproachesEulerBernoulliWithRefinement) {
  std::vector<double> errors;
  for (const auto& cells : {std::array<int, 3>{25, 1, 1}, {50, 2, 2}, {100, 4, 4}}) {
    const Propped p = propped_cantilever(cells);
    const double theory = 3.0 / 8.0 * p.weight;
    errors.push_back(std::abs(p.reaction - theory) / theory);
    std::cout << "cells " << cells[0] << "x" << cells[1] << "x" << cells[2] << ": reaction "
              << p.reaction << " N, 3/8 qL " << theory << " N, error " << errors.back() << "\n";
  }
  // Measured 0.25 %, 0.088 %, 0.038 %: each refinement must at least halve the error.
  EXPECT_LT(errors[1], errors[0] / 2);
  EXPECT_LT(errors[2], errors[1] / 2);
  EXPECT_LT(errors[2], 1e-3);
}

}  // namespace
}  // namespace shapectl
