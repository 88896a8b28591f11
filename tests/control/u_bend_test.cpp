// Self-contact driven by the robot (issue 34): the YuMi, both arms, bends its foam bar
// (scenes/yumi_bar_u.json: the bundled bar, gripped 7 cm in from each end) into a U until the
// ends touch. Only the end faces have targets; the optimizer finds all 14 joints. With
// self-contact the ends stop at a gap in (0, d̂]; without it the same targets pass them through
// each other. Whether the surface passes through itself is judged by tests/support's own
// triangle–triangle test, not contact/'s.
#include <shapectl/control/optimize.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include <shapectl/scene_io/scene_file.hpp>

#include "support/self_intersection.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

constexpr double kHalf = 0.16;  // the bar's half length, m

// The bar's end faces, each as the nodes of a cross on it (9 a face), and where each end's grip
// holds it: the centre of its gripped nodes at rest (world).
struct Ends {
  std::vector<int> nodes[2];  // [0]: the +x end (left grip), [1]: the −x end (right grip)
  int centre[2] = {-1, -1};   // each face's centre node
  Vec3 grip[2];
};

Ends ends_of(const GrippedObject& object) {
  Ends ends;
  const TetMesh& mesh = *object.scene().object_mesh;  // object frame: the bar along x
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Vec3& p = mesh.rest_positions()[i];
    const bool on_cross = std::abs(p.y()) < 1e-6 || std::abs(p.z()) < 1e-6;
    if (!on_cross || std::abs(std::abs(p.x()) - kHalf) > 1e-6) continue;
    ends.nodes[p.x() < 0].push_back(i);
    if (std::abs(p.y()) < 1e-6 && std::abs(p.z()) < 1e-6) ends.centre[p.x() < 0] = i;
  }
  const Positions rest = object.reference_positions();
  for (int e = 0; e < 2; ++e) {
    const Grip& grip = object.scene().grips[e];
    ends.grip[e] = Vec3::Zero();
    for (int i : grip.nodes) ends.grip[e] += rest.segment<3>(3 * i);
    ends.grip[e] /= static_cast<double>(grip.nodes.size());
  }
  return ends;
}

// Targets for the end faces at bend angle φ: each end turned rigidly by φ about the world x axis
// through its grip (the +y end clockwise seen from +x, so both ends swing down and inwards),
// the grips drawn together to the chord of a circular arc of the bar between them turning by
// 2φ: the free middle neither stretched nor pushed.
ShapeTargets bend_targets(const Ends& ends, const Positions& rest, double phi) {
  const Vec3 centre = 0.5 * (ends.grip[0] + ends.grip[1]);
  ShapeTargets t;
  for (int e = 0; e < 2; ++e) {
    const double side = e == 0 ? 1 : -1;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(-side * phi, Vec3::UnitX()).toRotationMatrix();
    const Vec3 half_span = ends.grip[e] - centre;
    const Vec3 grip = centre + half_span * std::sin(phi) / phi;
    for (int i : ends.nodes[e]) {
      t.nodes.push_back(i);
      t.positions.push_back(grip + turn * (rest.segment<3>(3 * i) - ends.grip[e]));
    }
  }
  return t;
}

// The bend angle at which the two end faces' centres meet at one point midway between the grips
// (the face centres are `arm` from their grips, the grips `span` apart at rest): the root in
// (π/2, π) of span/2 · sin φ/φ + arm · cos φ = 0, by bisection.
double meeting_angle(double span, double arm) {
  const auto y = [&](double phi) { return span / 2 * std::sin(phi) / phi + arm * std::cos(phi); };
  double lo = M_PI / 2, hi = M_PI;
  for (int k = 0; k < 60; ++k) (y(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// The distance between the two end faces' centres at x.
double ends_apart(const Ends& ends, const Positions& x) {
  return (x.segment<3>(3 * ends.centre[0]) - x.segment<3>(3 * ends.centre[1])).norm();
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

struct Bend {
  Evaluation state;
  OptimizeResult last;  // the last stage's run
  int iterations = 0;
};

// The optimizer run from `start` through the targets of each angle in turn, each stage from the
// state the last one reached (as a user dragging the ends in steps would do).
Bend bend(const ReducedObjective& base, const Ends& ends, const Positions& rest,
          const std::vector<double>& angles, Evaluation start) {
  Bend b{std::move(start), {}, 0};
  auto optimizer = make_optimizer(OptimizerKind::GaussNewton, GradientMethod::Sensitivity);
  for (double phi : angles) {
    const ReducedObjective objective = base.with_targets(bend_targets(ends, rest, phi));
    objective.rescore(b.state);
    const auto t0 = std::chrono::steady_clock::now();
    b.last = optimize(objective, *optimizer, b.state, {.max_iterations = 100, .max_seconds = 300});
    b.iterations += b.last.iterations;
    b.state = b.last.best;
    std::cout << "  bend " << phi * 180 / M_PI << " deg: mean error " << b.state.error.mean * 1e3
              << " mm, " << b.last.iterations << " iterations, " << seconds_since(t0) << " s ("
              << b.last.reason << ")\n";
  }
  return b;
}

TEST(UBend, TheYumiBendsTheBarIntoAUUntilItsEndsTouch) {
  const Scene scene = load_scene(test::source_path("scenes/yumi_bar_u.json"));
  ASSERT_TRUE(scene.contact.self && scene.contact.robot);
  const GrippedObject object(scene);
  const ReducedObjective base(object);
  const Positions rest = object.reference_positions();
  const Ends ends = ends_of(object);
  ASSERT_EQ(ends.nodes[0].size(), 9u);
  ASSERT_EQ(ends.nodes[1].size(), 9u);
  ASSERT_GE(ends.centre[0], 0);
  ASSERT_GE(ends.centre[1], 0);
  const double span = (ends.grip[0] - ends.grip[1]).norm();
  const double arm = (rest.segment<3>(3 * ends.centre[0]) - ends.grip[0]).norm();
  const double meet = meeting_angle(span, arm);
  // 10° steps (20° ones work too, in more iterations; the last stage given at once stops
  // after 9 iterations with the ends still 290 mm apart).
  constexpr int kStages = 12;
  std::vector<double> angles;
  for (int k = 1; k <= kStages; ++k) angles.push_back(meet * k / kStages);

  const auto t0 = std::chrono::steady_clock::now();
  const Evaluation start = base.evaluate(object.reference_joints(), rest);
  ASSERT_TRUE(start.statics().converged()) << start.statics().reason;
  std::cout << "self-contact on (ends meet at " << meet * 180 / M_PI << " deg):\n";
  const std::vector<double> approach(angles.begin(), angles.end() - 1);
  const Bend before = bend(base, ends, rest, approach, start);
  const SelfContact& self = *object.statics().self_contact();
  // No self pair within d̂ before the last stage: the model without self-contact agrees up to it.
  const double gap_before = self.min_distance(before.state.positions());
  ASSERT_GT(gap_before, scene.contact.distance);
  const Bend with = bend(base, ends, rest, {angles.back()}, before.state);
  const Positions& x = with.state.positions();
  ElementNodes pairs;
  self.hessian_elements(x, pairs);
  const double gap = self.min_distance(x);
  // The robot's spheres as obstacles, placed at the joints reached.
  const std::optional<ObstacleContact> posed = object.contact_at(*with.state.state);
  ASSERT_TRUE(posed.has_value());
  const ContactSummary robot = posed->summary(x);
  std::cout << "  end faces' centres " << ends_apart(ends, rest) * 1e3 << " mm apart at rest, "
            << ends_apart(ends, before.state.positions()) * 1e3 << " mm before the last stage "
            << "(smallest self gap " << gap_before * 1e3 << " mm), " << ends_apart(ends, x) * 1e3
            << " mm at its end\n";
  std::cout << "  smallest self gap " << gap * 1e3 << " mm, " << pairs.size()
            << " self pairs within d̂, " << robot.count << " pairs with the robot's spheres ("
            << robot.force_total.norm() << " N, smallest gap " << robot.min_distance * 1e3
            << " mm), "
            << "robot clearance " << with.state.min_clearance * 1e3 << " mm, "
            << before.iterations + with.iterations << " iterations, " << seconds_since(t0)
            << " s\n";
  EXPECT_TRUE(with.last.converged()) << with.last.reason;
  EXPECT_TRUE(with.state.safe());
  EXPECT_GT(gap, 0);
  EXPECT_LE(gap, scene.contact.distance) << "the ends touch";
  EXPECT_GT(pairs.size(), 0u);
  // What touches is the ends: every node of every pair within d̂ lies beyond the grips.
  for (int i : pairs.nodes)
    EXPECT_GT(std::abs(object.scene().object_mesh->rest_positions()[i].x()), 0.1) << "node " << i;
  EXPECT_LT(ends_apart(ends, x), 0.04);  // the faces' centres, 3 cm bar: side by side
  EXPECT_GT(with.state.min_clearance, 0) << "the robot clear of itself";
  EXPECT_GT(robot.min_distance, 0) << "the bar clear of the robot";
  const auto triangles = object.mesh().surface_triangles();
  EXPECT_EQ(test::self_intersection(x, triangles), "");

  // The same last stage without self-contact, from the same state: the ends pass through each
  // other.
  Scene free_scene = scene;
  free_scene.contact.self = false;
  const GrippedObject free_object(free_scene);
  const ReducedObjective free_base(free_object);
  const Evaluation free_start = free_base.evaluate(before.state.joints(), before.state.positions());
  ASSERT_TRUE(free_start.statics().converged()) << free_start.statics().reason;
  std::cout << "self-contact off:\n";
  const Bend without = bend(free_base, ends, rest, {angles.back()}, free_start);
  std::cout << "  end faces' centres " << ends_apart(ends, without.state.positions()) * 1e3
            << " mm apart\n";
  EXPECT_NE(test::self_intersection(without.state.positions(), triangles), "");
}

}  // namespace
}  // namespace shapectl
