// No equilibrium passes through an obstacle or through itself (issue 34): random obstacles near
// a sagging cantilever and under a bar two arms move at random, with self-contact on; every
// converged state is checked against every obstacle and against itself with tests/support's own
// geometry, not contact/'s.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "support/obstacle_clearance.hpp"
#include "support/self_intersection.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

using test::ObstacleShape;
using Kind = ObstacleShape::Kind;

// Each obstacle of `shapes` against the state x of `mesh`; empty when all are clear.
std::string first_intersection(const TetMesh& mesh, const Positions& x,
                               const std::vector<ObstacleShape>& shapes) {
  const auto triangles = mesh.surface_triangles();
  for (std::size_t k = 0; k < shapes.size(); ++k)
    if (const std::string what = test::intersection(x, triangles, shapes[k]); !what.empty())
      return "obstacle " + std::to_string(k) + ": " + what;
  return "";
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

// An obstacle somewhere under (or beside) a bar along x in [-0.15, 0.15] whose cross-section
// spans ±15 mm, within the reach of its sag; it may start anywhere clear of the bar.
ObstacleShape random_obstacle(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  ObstacleShape s;
  const double x = in(-0.05, 0.2), y = in(-0.03, 0.03), below = in(0.0005, 0.025);
  switch (static_cast<int>(4 * u(rng))) {
    case 0:
      s.kind = Kind::Plane;
      s.normal = Vec3(in(-0.3, 0.3), in(-0.3, 0.3), 1).normalized();
      s.point = Vec3(x, y, -0.015 - below - 0.01);
      break;
    case 1:
      s.kind = Kind::Sphere;
      s.radius = in(0.003, 0.03);
      s.a = Vec3(x, y, -0.015 - below - s.radius);
      break;
    case 2: {
      s.kind = Kind::Capsule;
      s.radius = in(0.002, 0.015);
      const Vec3 axis = random_rotation(rng) * Vec3::UnitX() * in(0.01, 0.05);
      const Vec3 c(x, y, -0.015 - below - s.radius - std::abs(axis.z()));
      s.a = c + axis;
      s.b = c - axis;
      break;
    }
    default: {
      s.kind = Kind::Box;
      s.size = Vec3(in(0.005, 0.06), in(0.005, 0.06), in(0.005, 0.06));
      s.pose.linear() = random_rotation(rng);
      const double reach = 0.5 * s.size.norm();  // the box's corners lie within it
      s.pose.translation() = Vec3(x, y, -0.015 - below - reach);
      break;
    }
  }
  return s;
}

// 150 placements of 1-2 obstacles under a soft cantilever that sags ~6 cm unsupported.
TEST(NoIntersection, RandomObstaclesUnderASaggingCantilever) {
  std::mt19937 rng(34);
  int converged = 0, touching = 0, placements = 0;
  while (placements < 150) {
    Scene scene;
    scene.source = "cantilever";
    scene.object_mesh =
        std::make_shared<const TetMesh>(make_box_mesh({0.3, 0.03, 0.03}, {10, 2, 2}));
    scene.material = material_from_youngs(2e5, 0.3, 100);
    scene.fixed = NodeSelection{.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-0.15 + 1e-6, 1, 1)}};
    scene.contact.distance = 1e-3;
    scene.contact.self = true;
    std::vector<ObstacleShape> shapes;
    for (int k = 1 + static_cast<int>(rng() % 2); k > 0; --k)
      shapes.push_back(random_obstacle(rng));
    const Positions rest = scene.world_rest_positions();
    // Placements that start touching are drawn again (both judges must see them clear).
    if (!first_intersection(*scene.object_mesh, rest, shapes).empty()) continue;
    for (std::size_t k = 0; k < shapes.size(); ++k)
      scene.obstacles.push_back(shapes[k].obstacle("o" + std::to_string(k)));
    const ObjectStatics statics(scene);
    if (statics.contact()->first_intersection(rest)[0] >= 0) continue;
    ++placements;
    Positions x = rest;
    const StaticsResult r = statics.solve(x);
    if (!r.converged()) continue;
    ++converged;
    touching += statics.contact()->summary(x).count > 0;
    ASSERT_EQ(first_intersection(statics.mesh(), x, shapes), "")
        << "placement " << placements << " (" << r.reason << ")";
    ASSERT_EQ(test::self_intersection(x, statics.mesh().surface_triangles()), "")
        << "placement " << placements;
  }
  std::cout << converged << " of 150 converged, " << touching << " of them touching\n";
  EXPECT_GE(converged, 120);  // the check means something only for accepted states
  EXPECT_GE(touching, 60);
}

// Two arms move a gripped bar over a table and a box on it: 50 random poses around the reference
// joints (±0.06 rad per joint, shoulders lowered by 0.03 rad on average: the tools go up to
// ~4 cm down), each solved from the last equilibrium carried to it. Every warm start and every
// converged state stays clear.
TEST(NoIntersection, ArmsPushAGrippedBarOntoATableAndABox) {
  Scene scene = test::two_arm_scene({12, 2, 2});
  const Positions rest = scene.world_rest_positions();
  double bottom = INFINITY;
  for (int i = 0; i < static_cast<int>(rest.size() / 3); ++i)
    bottom = std::min(bottom, rest[3 * i + 2]);
  const Vec3 centre = scene.T_world_object.translation();
  std::vector<ObstacleShape> shapes(2);
  shapes[0].kind = Kind::Plane;
  shapes[0].point = Vec3(0, 0, bottom - 0.04);
  shapes[1].kind = Kind::Box;
  shapes[1].size = Vec3(0.04, 0.04, 0.04);
  shapes[1].pose.translation() = Vec3(centre.x(), centre.y(), bottom - 0.008 - 0.02);
  shapes[1].pose.linear() = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  scene.contact.distance = 1e-3;
  scene.contact.self = true;
  for (std::size_t k = 0; k < shapes.size(); ++k)
    scene.obstacles.push_back(shapes[k].obstacle(k == 0 ? "table" : "box"));
  // Contact takes Newton many more iterations than free motion (20-200 here, 5-19 without the
  // obstacles): CCD keeps steps short while nodes slide at small gaps.
  scene.statics.max_iterations = 300;
  const GrippedObject object(scene);
  ObjectState current = object.solve_from(object.reference_joints(), rest);
  ASSERT_TRUE(current.statics().converged()) << current.statics().reason;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  int converged = 0, touching = 0;
  for (int step = 0; step < 50; ++step) {
    Eigen::VectorXd joints = object.reference_joints();
    for (int j = 0; j < joints.size(); ++j) joints[j] += u(rng);
    joints[1] += 0.03;  // shoulders: lower the tools
    joints[4] += 0.03;
    Positions x = current.positions();
    object.carry_gripped_nodes(current.joints(), joints, current.positions(), x);
    ASSERT_EQ(object.statics().contact()->first_intersection(x)[0], -1)
        << "warm start, step " << step;
    ObjectState next = object.solve_from(joints, x, 0, &current);
    // A carried start may invert an element next to a grip: then from the last equilibrium, as
    // the optimizer does (evaluate_predicted).
    if (next.statics().status == StaticsStatus::Inverted && next.statics().iterations == 0)
      next = object.solve_from(joints, current.positions(), 0, &current);
    if (!next.statics().converged()) {
      std::cout << "step " << step << ": " << next.statics().reason << "\n";
      continue;
    }
    ++converged;
    touching += object.statics().contact()->summary(next.positions()).count > 0;
    ASSERT_EQ(first_intersection(object.mesh(), next.positions(), shapes), "") << "step " << step;
    ASSERT_EQ(test::self_intersection(next.positions(), object.mesh().surface_triangles()), "")
        << "step " << step;
    current = std::move(next);
  }
  std::cout << converged << " of 50 converged, " << touching << " touching\n";
  EXPECT_GE(converged, 35);
  EXPECT_GE(touching, 20);
}

}  // namespace
}  // namespace shapectl
