#include <shapectl/calib/surface_distance.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

// A box mesh bent along x, twisted and shaken: no symmetry the tree could lean on.
Positions deformed(const TetMesh& mesh, double noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-noise, noise);
  Positions x = mesh.rest_vector();
  for (int i = 0; i < mesh.node_count(); ++i) {
    Vec3 p = x.segment<3>(3 * i);
    p.z() += 0.3 * p.x() * p.x() + 0.2 * p.x() * p.y();
    x.segment<3>(3 * i) = p + Vec3(u(rng), u(rng), u(rng));
  }
  return x;
}

Vec3 corner(const Positions& x, int node) { return x.segment<3>(3 * node); }

// The smallest distance from p to any triangle, one by one.
double brute_force_distance(const std::vector<std::array<int, 3>>& triangles, const Positions& x,
                            const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : triangles) {
    const Vec3 a = corner(x, t[0]), b = corner(x, t[1]), c = corner(x, t[2]);
    const Eigen::Vector3d w = closest_on_triangle(p, a, b, c);
    best = std::min(best, (p - (w[0] * a + w[1] * b + w[2] * c)).norm());
  }
  return best;
}

// The distance to the surface with the tree rebuilt: the exact function to differentiate.
double surface_distance(SurfaceDistance& surface, const Positions& x, const Vec3& p) {
  surface.update(x);
  return surface.closest(p).distance;
}

TEST(SurfaceDistance, EachRegionOfATriangleGivesItsClosestPoint) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    const char* region;
    Vec3 p;
    Eigen::Vector3d barycentric;
  };
  const Case cases[] = {
      {"vertex a", {-1, -1, 0.5}, {1, 0, 0}},
      {"vertex b", {2, -0.5, 0.3}, {0, 1, 0}},
      {"vertex c", {-0.5, 2, -0.2}, {0, 0, 1}},
      {"edge ab", {0.5, -1, 0.2}, {0.5, 0.5, 0}},
      {"edge ac", {-1, 0.3, 0}, {0.7, 0, 0.3}},
      {"edge bc", {1, 1, 0.5}, {0, 0.5, 0.5}},
      {"face", {0.2, 0.3, 0.7}, {0.5, 0.2, 0.3}},
      {"face below", {0.25, 0.25, -2}, {0.5, 0.25, 0.25}},
  };
  SurfaceDistance surface({{0, 1, 2}});
  Positions x(9);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0;  // a, b, c
  surface.update(x);
  for (const Case& k : cases) {
    const Eigen::Vector3d w = closest_on_triangle(k.p, a, b, c);
    EXPECT_LT((w - k.barycentric).norm(), 1e-14) << k.region << ": " << w.transpose();
    const SurfaceHit hit = surface.closest(k.p);
    const Vec3 expected = k.barycentric[0] * a + k.barycentric[1] * b + k.barycentric[2] * c;
    EXPECT_LT((hit.point - expected).norm(), 1e-14) << k.region;
    EXPECT_NEAR(hit.distance, (k.p - expected).norm(), 1e-14) << k.region;
    EXPECT_EQ(hit.triangle, 0);
    EXPECT_EQ(hit.nodes, (std::array<int, 3>{0, 1, 2}));
  }
}

// c is the closest point of a convex set to p exactly when (p − c)·(q − c) <= 0 for every q in
// it; for a triangle the corners suffice. Checked on random, thin and degenerate triangles.
TEST(SurfaceDistance, ClosestOnTriangleMeetsTheProjectionCondition) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  auto random_vec = [&] { return Vec3(n(rng), n(rng), n(rng)); };
  for (int trial = 0; trial < 3000; ++trial) {
    std::array<Vec3, 3> t{random_vec(), random_vec(), random_vec()};
    if (trial % 5 == 1) t[2] = t[0] + 1e-9 * random_vec();  // a sliver
    if (trial % 5 == 2) t[2] = 0.3 * t[0] + 0.7 * t[1];     // collinear
    if (trial % 5 == 3) t[1] = t[0];                        // two corners coincide
    if (trial % 5 == 4) t[1] = t[2] = t[0];                 // a point
    const Vec3 p = 2 * random_vec();
    const Eigen::Vector3d w = closest_on_triangle(p, t[0], t[1], t[2]);
    ASSERT_TRUE(w.allFinite()) << trial;
    EXPECT_GE(w.minCoeff(), 0) << trial;
    EXPECT_NEAR(w.sum(), 1, 1e-14) << trial;
    const Vec3 c = w[0] * t[0] + w[1] * t[1] + w[2] * t[2];
    // A sliver 1e-9 thick is resolved to about its thickness.
    const double tolerance = trial % 5 == 1 ? 1e-8 : 1e-12;
    for (const Vec3& q : t) EXPECT_LE((p - c).dot(q - c), tolerance) << trial;
  }
}

TEST(SurfaceDistance, TreeAgreesWithBruteForceOnADeformedBox) {
  const TetMesh mesh = make_box_mesh({0.3, 0.08, 0.05}, {9, 3, 2});
  const auto triangles = mesh.surface_triangles();
  std::mt19937 rng(42);
  SurfaceDistance surface(triangles);
  int faces = 0, edges = 0, vertices = 0;
  for (int shape = 0; shape < 3; ++shape) {
    const Positions x = deformed(mesh, 0.004, rng);
    surface.update(x);
    std::uniform_real_distribution<double> ux(-0.25, 0.25), uy(-0.1, 0.1), uz(-0.1, 0.15);
    for (int k = 0; k < 2000; ++k) {
      const Vec3 p(ux(rng), uy(rng), uz(rng));
      const SurfaceHit hit = surface.closest(p);
      ASSERT_GE(hit.triangle, 0);
      EXPECT_EQ(hit.nodes, triangles[hit.triangle]);
      const Vec3 c = hit.barycentric[0] * corner(x, hit.nodes[0]) +
                     hit.barycentric[1] * corner(x, hit.nodes[1]) +
                     hit.barycentric[2] * corner(x, hit.nodes[2]);
      EXPECT_LT((c - hit.point).norm(), 1e-15);
      EXPECT_NEAR(hit.distance, (p - c).norm(), 1e-15);
      EXPECT_EQ(hit.distance, brute_force_distance(triangles, x, p)) << p.transpose();
      const int zeros = (hit.barycentric.array() == 0).count();
      (zeros == 0 ? faces : zeros == 1 ? edges : vertices)++;
    }
  }
  // The points reach every kind of closest feature.
  EXPECT_GT(faces, 100);
  EXPECT_GT(edges, 100);
  EXPECT_GT(vertices, 10);
}

// d(distance)/dx_{nodes[k]} = −bₖ (p − c)/|p − c| with b held fixed, against central differences
// of the exact distance (tree rebuilt per step), for every coordinate of x.
TEST(SurfaceDistance, DistanceDerivativeWithFixedBarycentricsMatchesCentralDifferences) {
  const TetMesh mesh = make_box_mesh({0.2, 0.05, 0.04}, {4, 1, 1});
  const auto triangles = mesh.surface_triangles();
  std::mt19937 rng(3);
  const Positions x = deformed(mesh, 0.003, rng);
  SurfaceDistance surface(triangles);
  std::uniform_real_distribution<double> ux(-0.14, 0.14), uy(-0.06, 0.06), uz(-0.05, 0.06);
  const double h = 1e-7;
  int checked = 0, checked_faces = 0, checked_elsewhere = 0;
  for (int k = 0; k < 200 && checked < 40; ++k) {
    const Vec3 p(ux(rng), uy(rng), uz(rng));
    surface.update(x);
    const SurfaceHit hit = surface.closest(p);
    if (hit.distance < 1e-3) continue;
    // Skip ties: another triangle nearly as close through a different closest point, where
    // the distance has a kink.
    bool tie = false;
    for (const auto& t : triangles) {
      const Vec3 a = corner(x, t[0]), b = corner(x, t[1]), c = corner(x, t[2]);
      const Eigen::Vector3d w = closest_on_triangle(p, a, b, c);
      const Vec3 q = w[0] * a + w[1] * b + w[2] * c;
      if ((p - q).norm() - hit.distance < 1e-4 && (q - hit.point).norm() > 1e-9) tie = true;
    }
    if (tie) continue;
    Positions analytic = Positions::Zero(x.size());
    const Vec3 normal = (p - hit.point) / hit.distance;
    for (int c = 0; c < 3; ++c)
      analytic.segment<3>(3 * hit.nodes[c]) += -hit.barycentric[c] * normal;
    Positions numeric(x.size());
    for (int i = 0; i < x.size(); ++i) {
      Positions plus = x, minus = x;
      plus[i] += h;
      minus[i] -= h;
      numeric[i] =
          (surface_distance(surface, plus, p) - surface_distance(surface, minus, p)) / (2 * h);
    }
    ASSERT_GT(analytic.norm(), 0.5);  // Σ bₖ = 1: never a comparison of zeros
    EXPECT_LT((numeric - analytic).lpNorm<Eigen::Infinity>(), 1e-6)
        << "p " << p.transpose() << " barycentric " << hit.barycentric.transpose();
    ++checked;
    ((hit.barycentric.array() > 0).all() ? checked_faces : checked_elsewhere)++;
  }
  EXPECT_EQ(checked, 40);
  EXPECT_GT(checked_faces, 5);
  EXPECT_GT(checked_elsewhere, 5);
}

TEST(SurfaceDistance, MisuseIsRefused) {
  EXPECT_THROW(SurfaceDistance({}), std::invalid_argument);
  EXPECT_THROW(SurfaceDistance({{0, -1, 2}}), std::invalid_argument);
  SurfaceDistance surface({{0, 1, 2}});
  EXPECT_THROW(surface.closest(Vec3::Zero()), std::logic_error);
  EXPECT_THROW(surface.update(Positions::Zero(6)), std::invalid_argument);
  Positions x = Positions::Zero(9);
  x[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(surface.update(x), std::invalid_argument);
  x[4] = 1;
  surface.update(x);
  EXPECT_THROW(surface.closest(Vec3(0, std::nan(""), 0)), std::invalid_argument);
}

}  // namespace
}  // namespace shapectl
