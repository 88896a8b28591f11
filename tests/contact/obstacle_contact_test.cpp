// The contact energy against obstacles: derivatives against central differences with many
// active pairs of every kind, PSD projection, summary, CCD and intersection queries.
#include <shapectl/contact/obstacle_contact.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

constexpr double kDhat = 0.01;  // large enough that central differences (h = 1e-6) resolve b

Positions translated(const TetMesh& mesh, const Vec3& offset) {
  Positions x = mesh.rest_vector();
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) += offset;
  return x;
}

// The object: a 0.1 × 0.1 × 0.02 box whose centre sits at the origin.
TetMesh object_mesh() { return make_box_mesh({0.1, 0.1, 0.02}, {4, 4, 1}); }

std::vector<Obstacle> octahedron(const Vec3& centre, double size) {
  std::vector<Vec3> v{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (Vec3& p : v) p = centre + size * p;
  return {make_mesh_obstacle(
      "octahedron", v,
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}})};
}

// Every kind of obstacle within d̂ of some part of the object (its bottom at z = −0.01, top at
// 0.01, sides at ±0.05), at gaps of about d̂/2.
std::vector<Obstacle> every_kind() {
  const double gap = 0.4 * kDhat;
  std::vector<Obstacle> o;
  o.push_back(make_plane("table", Vec3(0, 0, -0.01 - gap), Vec3(0, 0, 1)));
  // A box turned about z and x so its edges are skew to the object's, its lowest-x corner at
  // the gap from the +x face.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(0.3, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitX()));
  Obstacle block = make_box("block", Vec3(0.04, 0.04, 0.01), T);
  double lowest = 1;
  for (const Vec3& p : block.points) lowest = std::min(lowest, p.x());
  T.pretranslate(Vec3(0.05 + gap - lowest, 0.01, 0.002));
  o.push_back(make_box("block", Vec3(0.04, 0.04, 0.01), T));
  o.push_back(make_sphere("ball", Vec3(0.013, 0.011, 0.01 + gap + 0.02), 0.02));
  // Across the −y face at mid height, skew to the object's edges.
  o.push_back(make_capsule("bar", Vec3(-0.04, -0.05 - gap - 0.003, 0.004),
                           Vec3(0.04, -0.05 - gap - 0.003, -0.002), 0.003));
  // A corner poking at the −x face.
  o.push_back(octahedron(Vec3(-0.05 - gap - 0.02, 0.007, 0.003), 0.02)[0]);
  return o;
}

TEST(ObstacleContact, DerivativesMatchCentralDifferencesWithEveryKindOfObstacle) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, every_kind(), kDhat, 3.0);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    const Positions x = test::perturbed(mesh.rest_vector(), 0.1 * kDhat, rng);
    const ContactSummary s = contact.summary(x);
    EXPECT_GE(s.count, 20);
    ASSERT_EQ(s.by_obstacle.size(), 5u);
    for (std::size_t o = 0; o < 5; ++o)
      EXPECT_GT(s.by_obstacle[o].count, 0) << contact.obstacles()[o].name << " touches nothing";
    EXPECT_GT(s.min_distance, 0.1 * kDhat);  // central differences resolve the barrier
    EXPECT_TRUE(std::isfinite(contact.value(x)));
    test::expect_derivatives_match(contact, x, 1e-5);
  }
}

TEST(ObstacleContact, EnergyIsTheBarrierSumOverVerticesAboveAPlane) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, {make_plane("table", Vec3::Zero(), Vec3::UnitZ())}, kDhat,
                                2.0);
  std::mt19937 rng(3);
  Positions x = translated(mesh, Vec3(0, 0, 0.01 + 0.5 * kDhat));
  x = test::perturbed(x, 0.3 * kDhat, rng);
  double expected = 0;
  int count = 0;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (x[3 * i + 2] < kDhat) {
      expected += 2.0 * barrier(x[3 * i + 2], kDhat).value;
      ++count;
    }
  EXPECT_EQ(count, 25);
  EXPECT_NEAR(contact.value(x), expected, 1e-12 * expected);
  EXPECT_EQ(contact.summary(x).count, count);
  test::expect_derivatives_match(contact, x, 1e-5);
  // Through the plane: +inf.
  x[2] = -1e-4;
  EXPECT_EQ(contact.value(x), std::numeric_limits<double>::infinity());
}

TEST(ObstacleContact, CountsEachContactOnceHoweverManyTrianglesFindIt) {
  // The object over a closed plate meshed like its own bottom: each bottom vertex sits right
  // above a plate vertex that six plate triangles, several plate edges and several object
  // triangles all find. Counted once each, the energy is the plane's: 25 barriers.
  const TetMesh mesh = object_mesh();
  const double gap = 0.4 * kDhat;
  std::vector<Vec3> plate = mesh.rest_positions();
  for (Vec3& p : plate) p.z() -= 0.02 + gap;
  const ObstacleContact on_mesh(mesh,
                                {make_mesh_obstacle("plate", plate, mesh.surface_triangles())},
                                kDhat, 2.0);
  const ObstacleContact on_plane(mesh,
                                 {make_plane("table", Vec3(0, 0, -0.01 - gap), Vec3::UnitZ())},
                                 kDhat, 2.0);
  const Positions x = mesh.rest_vector();
  EXPECT_EQ(on_mesh.summary(x).count, 25);
  EXPECT_NEAR(on_mesh.value(x), 25 * 2.0 * barrier(gap, kDhat).value, 1e-9 * on_plane.value(x));
  EXPECT_NEAR(on_mesh.value(x), on_plane.value(x), 1e-9 * on_plane.value(x));
}

// Collects every block a term gives, in order.
class BlockSink : public ElementHessianSink {
 public:
  explicit BlockSink(const ElementNodes& elements) : elements_(elements) {}
  void add_blocks(const ElementKernel& kernel) override {
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const int dofs = 3 * elements_.node_count(e);
      Eigen::MatrixXd block(dofs, dofs);
      block.setConstant(std::numeric_limits<double>::quiet_NaN());
      kernel(e, block.data());
      blocks.push_back(block);
    }
  }
  std::vector<Eigen::MatrixXd> blocks;

 private:
  const ElementNodes& elements_;
};

std::vector<Eigen::MatrixXd> blocks(const EnergyTerm& term, const Positions& x, bool project) {
  ElementNodes elements;
  term.hessian_elements(x, elements);
  BlockSink sink(elements);
  term.add_hessian(x, sink, project);
  EXPECT_EQ(sink.blocks.size(), elements.size());
  return sink.blocks;
}

double smallest_eigenvalue(const Eigen::MatrixXd& block) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(block).eigenvalues().minCoeff();
}

TEST(ObstacleContact, ProjectionMakesEveryBlockPositiveSemiDefinite) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, every_kind(), kDhat, 3.0);
  std::mt19937 rng(12);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.1 * kDhat, rng);
  const auto exact = blocks(contact, x, false), projected = blocks(contact, x, true);
  int indefinite = 0, nonzero = 0;
  for (std::size_t e = 0; e < exact.size(); ++e) {
    ASSERT_TRUE(exact[e].allFinite() && projected[e].allFinite()) << "element " << e;
    const double scale = exact[e].cwiseAbs().maxCoeff();
    if (scale == 0) {
      EXPECT_EQ(projected[e].cwiseAbs().maxCoeff(), 0) << "element " << e;
      continue;
    }
    ++nonzero;
    if (smallest_eigenvalue(exact[e]) < -1e-9 * scale) ++indefinite;
    EXPECT_GE(smallest_eigenvalue(projected[e]), -1e-9 * scale) << "element " << e;
    EXPECT_LT((projected[e] - projected[e].transpose()).cwiseAbs().maxCoeff(), 1e-9 * scale);
  }
  EXPECT_GE(nonzero, 20);
  EXPECT_GT(indefinite, 0) << "no indefinite block: the projection was not exercised";
  // The projected Hessian as a whole, too.
  const Eigen::MatrixXd H = test::dense_hessian(contact, x, true);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff(),
            -1e-9 * H.cwiseAbs().maxCoeff());
}

TEST(ObstacleContact, SummaryForceIsMinusTheGradientSummed) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, every_kind(), kDhat, 3.0);
  std::mt19937 rng(13);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.1 * kDhat, rng);
  const Eigen::VectorXd g = test::energy_gradient(contact, x);
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < mesh.node_count(); ++i) total -= g.segment<3>(3 * i);
  const ContactSummary s = contact.summary(x);
  EXPECT_LT((s.force_total - total).norm(), 1e-9 * total.norm());
  EXPECT_GT(total.norm(), 0);
  Vec3 by_obstacle = Vec3::Zero(), by_point = Vec3::Zero();
  int count = 0;
  for (const auto& o : s.by_obstacle) {
    by_obstacle += o.force;
    count += o.count;
  }
  double smallest = std::numeric_limits<double>::infinity();
  for (const ContactPoint& p : s.points) {
    by_point += p.force;
    smallest = std::min(smallest, p.distance);
    EXPECT_GT(p.distance, 0);
    EXPECT_LT(p.distance, kDhat);
  }
  EXPECT_EQ(count, s.count);
  EXPECT_EQ(static_cast<int>(s.points.size()), s.count);
  EXPECT_EQ(smallest, s.min_distance);
  EXPECT_LT((by_obstacle - total).norm(), 1e-9 * total.norm());
  EXPECT_LT((by_point - total).norm(), 1e-9 * total.norm());
  // The table pushes up.
  EXPECT_GT(s.by_obstacle[0].force.z(), 0);
}

TEST(ObstacleContact, SummaryIsEmptyFarAway) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, every_kind(), kDhat, 3.0);
  const ContactSummary s = contact.summary(translated(mesh, Vec3(0, 0, 1)));
  EXPECT_EQ(s.count, 0);
  EXPECT_EQ(s.min_distance, std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.force_total, Vec3::Zero());
}

TEST(ObstacleContact, MaxStepIsOneFarAway) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, every_kind(), kDhat, 3.0);
  const Positions x = translated(mesh, Vec3(0, 0, 1));
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
  for (int i = 0; i < mesh.node_count(); ++i) dx.segment<3>(3 * i) = Vec3(0.01, -0.02, 0.1);
  EXPECT_EQ(contact.max_step(x, dx), 1.0);
}

TEST(ObstacleContact, MaxStepIsExactForAHalfSpace) {
  const TetMesh mesh = object_mesh();
  const ObstacleContact contact(mesh, {make_plane("table", Vec3::Zero(), Vec3(0, 0, 1))}, kDhat,
                                1.0);
  const double start = 0.004;  // the lowest nodes' gap
  const Positions x = translated(mesh, Vec3(0, 0, 0.01 + start));
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
  for (int i = 0; i < mesh.node_count(); ++i) dx.segment<3>(3 * i) = Vec3(0.02, 0.01, -0.05);
  const double alpha = contact.max_step(x, dx);
  EXPECT_NEAR(alpha, 0.9 * start / 0.05, 1e-14);
  EXPECT_NEAR(contact.summary(x + alpha * dx).min_distance, 0.1 * start, 1e-15);
}

// Whether anything intersects at one of many points on the way from x to x + dx.
bool intersects_on_the_way(const ObstacleContact& contact, const Positions& x,
                           const Eigen::VectorXd& dx) {
  for (int k = 0; k <= 1000; ++k)
    if (contact.first_intersection(x + (k / 1000.0) * dx)[0] >= 0) return true;
  return false;
}

// Moves x along dx to α and checks, at many points of the way, that nothing intersects.
void expect_no_intersection_on_the_way(const ObstacleContact& contact, const Positions& x,
                                       const Eigen::VectorXd& dx, double alpha) {
  for (int k = 0; k <= 200; ++k) {
    const Positions y = x + (alpha * k / 200) * dx;
    ASSERT_EQ(contact.first_intersection(y), (std::array<int, 2>{-1, -1})) << "at step " << k;
    ASSERT_TRUE(std::isfinite(contact.value(y))) << "at step " << k;
  }
}

// The object at rest (its bottom at z = −0.01) against `obstacle`, every node stepping by
// `step`: max_step cuts the step short of where the full one passes through the obstacle, and
// nothing intersects anywhere on the way to it. Returns α.
double expect_step_stopped(const TetMesh& mesh, const Obstacle& obstacle, const Vec3& step) {
  const ObstacleContact contact(mesh, {obstacle}, 0.001, 1.0);
  const Positions x = mesh.rest_vector();
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
  for (int i = 0; i < mesh.node_count(); ++i) dx.segment<3>(3 * i) = step;
  const double alpha = contact.max_step(x, dx);
  EXPECT_GT(alpha, 0);
  EXPECT_LT(alpha, 1);
  expect_no_intersection_on_the_way(contact, x, dx, alpha);
  // The full step does pass through: the checks above could fail.
  EXPECT_TRUE(intersects_on_the_way(contact, x, dx));
  return alpha;
}

TEST(ObstacleContact, MaxStepStopsAStepThroughAThinBox) {
  // A plate 1 mm thick, 5 mm below the object; the step would carry the object 10 cm down,
  // wholly through it.
  const TetMesh mesh = object_mesh();
  const Obstacle plate = make_box("plate", Vec3(0.3, 0.3, 0.001),
                                  Eigen::Isometry3d(Eigen::Translation3d(0, 0, -0.0155)));
  const double alpha = expect_step_stopped(mesh, plate, Vec3(0.01, 0.003, -0.1));
  EXPECT_LT(alpha, 0.05);  // 0.1 α ≤ 5 mm
  // The gap keeps at least 10 % of the 5 mm it started with.
  const ObstacleContact contact(mesh, {plate}, 0.001, 1.0);
  Positions y = mesh.rest_vector();
  for (int i = 0; i < mesh.node_count(); ++i)
    y.segment<3>(3 * i) += alpha * Vec3(0.01, 0.003, -0.1);
  EXPECT_GE(contact.summary(y).min_distance, 0.1 * 0.005 * (1 - 1e-9));
}

TEST(ObstacleContact, MaxStepStopsATriangleFallingOntoAPinBetweenItsVertices) {
  // One cell: the bottom face is two triangles 10 cm across; the pin, 4 mm wide and 1 mm thick,
  // sits under its middle, away from every vertex and edge of the object.
  const double alpha =
      expect_step_stopped(make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1}),
                          make_box("pin", Vec3(0.004, 0.004, 0.001),
                                   Eigen::Isometry3d(Eigen::Translation3d(0.02, -0.015, -0.0135))),
                          Vec3(0, 0, -0.1));
  EXPECT_LT(alpha, 0.03);
}

TEST(ObstacleContact, MaxStepStopsAnEdgeSweepingAcrossACapsule) {
  // A thin capsule (1 mm) crossing under the object's bottom edges; the object slides 10 cm
  // sideways and down: its edges would cut through the capsule between vertices.
  expect_step_stopped(make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1}),
                      make_capsule("wire", Vec3(0.08, -0.2, -0.0125), Vec3(0.08, 0.2, -0.0125),
                                   0.0005),
                      Vec3(0.1, 0, -0.004));
}

TEST(ObstacleContact, FirstIntersectionFindsAPlantedIntersection) {
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1});
  const auto triangles = mesh.surface_triangles();
  // A capsule through the middle of the top and bottom faces: no vertex near it.
  std::vector<Obstacle> obstacles{make_plane("table", Vec3(0, 0, -0.05), Vec3::UnitZ()),
                                  make_capsule("rod", Vec3(0.01, 0.02, -0.03),
                                               Vec3(0.01, 0.02, 0.03), 0.001)};
  const ObstacleContact contact(mesh, obstacles, 0.001, 1.0);
  const Positions x = mesh.rest_vector();
  const auto hit = contact.first_intersection(x);
  ASSERT_EQ(hit[0], 1);
  ASSERT_GE(hit[1], 0);
  // The triangle found is one the rod passes through: on the top or bottom face.
  for (int k : triangles[hit[1]]) EXPECT_NEAR(std::abs(x[3 * k + 2]), 0.01, 1e-12);
  // Lifted clear of the rod's ends: nothing; then one node pushed through the table.
  const ObstacleContact table_only(mesh, {obstacles[0]}, 0.001, 1.0);
  EXPECT_EQ(table_only.first_intersection(x), (std::array<int, 2>{-1, -1}));
  Positions y = x;
  y[2] = -0.06;  // node 0 below the table
  const auto below = table_only.first_intersection(y);
  ASSERT_EQ(below[0], 0);
  const auto& t = triangles[below[1]];
  EXPECT_TRUE(t[0] == 0 || t[1] == 0 || t[2] == 0);
}

TEST(ObstacleContact, FirstIntersectionFindsCrossingTriangles) {
  // A box obstacle through the middle of the object's faces with no corner of either inside the
  // other: only triangle against triangle finds it.
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1});
  const ObstacleContact contact(
      mesh, {make_box("beam", Vec3(0.01, 0.3, 0.01), Eigen::Isometry3d::Identity())}, 0.001, 1.0);
  EXPECT_EQ(contact.first_intersection(mesh.rest_vector())[0], 0);
  const ObstacleContact apart(mesh,
                              {make_box("beam", Vec3(0.01, 0.3, 0.01),
                                        Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.0151)))},
                              0.001, 1.0);
  EXPECT_EQ(apart.first_intersection(mesh.rest_vector())[0], -1);
}

TEST(DefaultContactStiffness, HoldsTheMeanNodalWeightAtHalfTheDistance) {
  const TetMesh mesh = object_mesh();
  const double weight = 3.7, dhat = 0.002;
  const double kappa = default_contact_stiffness(weight, mesh.node_count(), dhat);
  const ObstacleContact contact(mesh, {make_plane("table", Vec3::Zero(), Vec3::UnitZ())}, dhat,
                                kappa);
  // One node at d̂/2, the rest far above: the table holds it with the mean nodal weight.
  Positions x = translated(mesh, Vec3(0, 0, 1));
  x[2] = 0.5 * dhat;
  const ContactSummary s = contact.summary(x);
  ASSERT_EQ(s.count, 1);
  EXPECT_NEAR(s.force_total.z(), weight / mesh.node_count(), 1e-12 * weight);
  EXPECT_THROW(default_contact_stiffness(weight, 0, dhat), std::invalid_argument);
  EXPECT_THROW(default_contact_stiffness(weight, 10, 0), std::invalid_argument);
}

TEST(ObstacleContact, HessianElementsAreTheSurfaceVerticesEdgesAndTriangles) {
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {1, 1, 1});
  const ObstacleContact contact(mesh, every_kind(), kDhat, 1.0);
  ElementNodes elements;
  contact.hessian_elements(mesh.rest_vector(), elements);
  // A box of one cell: 8 vertices, 12 triangles, 18 edges.
  ASSERT_EQ(elements.size(), 8u + 18u + 12u);
  for (std::size_t e = 0; e < 8; ++e) EXPECT_EQ(elements.node_count(e), 1);
  for (std::size_t e = 8; e < 26; ++e) EXPECT_EQ(elements.node_count(e), 2);
  for (std::size_t e = 26; e < 38; ++e) EXPECT_EQ(elements.node_count(e), 3);
  ElementNodes again;
  contact.hessian_elements(mesh.rest_vector(), again);
  EXPECT_EQ(elements, again);
}

}  // namespace
}  // namespace shapectl
