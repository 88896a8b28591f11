// The test-side geometry (tests/support/triangle_intersection.hpp) the contact tests judge
// equilibria with: its own checks, so a "no intersection" verdict means something.
#include <gtest/gtest.h>

#include <random>

#include "support/triangle_intersection.hpp"

namespace shapectl::test {
namespace {

const Triangle kFloor = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};

Triangle moved(const Triangle& t, const Vec3& by) { return {t[0] + by, t[1] + by, t[2] + by}; }

TEST(TriangleIntersection, CrossingTrianglesIntersect) {
  const Triangle wall = {Vec3(0.2, 0.2, -0.5), Vec3(0.2, 0.2, 0.5), Vec3(0.6, -0.3, 0.1)};
  EXPECT_TRUE(triangles_intersect(kFloor, wall));
  EXPECT_TRUE(triangles_intersect(wall, kFloor));
  EXPECT_FALSE(triangles_intersect(kFloor, moved(wall, Vec3(0, 0, 0.6))));
  EXPECT_FALSE(triangles_intersect(kFloor, moved(wall, Vec3(2, 0, 0))));
}

TEST(TriangleIntersection, ANearMissIsNoIntersectionAndATouchIsOne) {
  // A triangle standing on the floor's hypotenuse, then lifted by 1e-9 m.
  const Triangle standing = {Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 1), Vec3(1, 1, 0.5)};
  EXPECT_TRUE(triangles_intersect(kFloor, standing));
  EXPECT_FALSE(triangles_intersect(kFloor, moved(standing, Vec3(0, 0, 1e-9))));
  // Vertex on vertex.
  const Triangle apex = {Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 1, 1)};
  EXPECT_TRUE(triangles_intersect(kFloor, apex));
  EXPECT_FALSE(triangles_intersect(kFloor, moved(apex, Vec3(1e-9, 0, 0))));
}

TEST(TriangleIntersection, AnEdgeThroughTheInteriorWithNoVertexInsideIntersects) {
  // Neither triangle has a vertex inside the other: only their edges' crossings show it.
  const Triangle spear = {Vec3(0.25, 0.25, -1), Vec3(0.25, 0.25, 1), Vec3(5, 5, 0.3)};
  EXPECT_TRUE(triangles_intersect(kFloor, spear));
}

TEST(TriangleIntersection, CoplanarTriangles) {
  EXPECT_TRUE(triangles_intersect(kFloor, moved(kFloor, Vec3(0.4, 0.4, 0))));
  EXPECT_FALSE(triangles_intersect(kFloor, moved(kFloor, Vec3(0.6, 0.6, 0))));
  // One inside the other, no edges crossing.
  const Triangle small = {Vec3(0.1, 0.1, 0), Vec3(0.2, 0.1, 0), Vec3(0.1, 0.2, 0)};
  EXPECT_TRUE(triangles_intersect(kFloor, small));
  EXPECT_TRUE(triangles_intersect(small, kFloor));
  // Star of David: edges cross, no vertex inside.
  const Triangle up = {Vec3(0, 1, 0), Vec3(-0.866, -0.5, 0), Vec3(0.866, -0.5, 0)};
  const Triangle down = {Vec3(0, -1, 0), Vec3(0.866, 0.5, 0), Vec3(-0.866, 0.5, 0)};
  EXPECT_TRUE(triangles_intersect(up, down));
}

// Random pairs: ones that share a constructed point intersect; ones a plane separates do not;
// the verdict never depends on the order of triangles or vertices.
TEST(TriangleIntersection, RandomPairsWithAKnownAnswer) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), w(0.05, 1);
  auto random_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  auto with_point = [&](const Vec3& p) {  // a random triangle containing p
    Triangle t = {random_vec(), random_vec(), random_vec()};
    const Vec3 b = Vec3(w(rng), w(rng), w(rng)) / 1.0;
    const Vec3 bary = b / b.sum();
    const Vec3 at = bary[0] * t[0] + bary[1] * t[1] + bary[2] * t[2];
    return moved(t, p - at);
  };
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p = random_vec();
    const Triangle a = with_point(p), b = with_point(p);
    ASSERT_TRUE(triangles_intersect(a, b)) << k;
    ASSERT_TRUE(triangles_intersect(b, a)) << k;
    ASSERT_TRUE(triangles_intersect({a[2], a[0], a[1]}, {b[1], b[0], b[2]})) << k;
    // Separated: every vertex of a on the far side of a random plane through p, b on the near.
    const Vec3 n = random_vec().normalized();
    Triangle far = a, near = b;
    for (Vec3& v : far) v += n * (std::max(0.0, -n.dot(v - p)) + 1e-6);
    for (Vec3& v : near) v -= n * (std::max(0.0, n.dot(v - p)) + 1e-6);
    ASSERT_FALSE(triangles_intersect(far, near)) << k;
    ASSERT_FALSE(triangles_intersect(near, far)) << k;
  }
}

TEST(TriangleIntersection, SegmentTriangle) {
  EXPECT_TRUE(segment_meets_triangle(Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), kFloor));
  EXPECT_FALSE(segment_meets_triangle(Vec3(0.2, 0.2, 1e-9), Vec3(0.2, 0.2, 1), kFloor));
  EXPECT_TRUE(segment_meets_triangle(Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), kFloor));
  EXPECT_FALSE(segment_meets_triangle(Vec3(0.8, 0.8, -1), Vec3(0.8, 0.8, 1), kFloor));
  // In the plane: across an edge, and beside the triangle.
  EXPECT_TRUE(segment_meets_triangle(Vec3(-1, 0.3, 0), Vec3(1, 0.3, 0), kFloor));
  EXPECT_FALSE(segment_meets_triangle(Vec3(-1, -0.3, 0), Vec3(1, -0.3, 0), kFloor));
}

// Distances against dense sampling: never above a sampled distance, and close to the best.
TEST(TriangleIntersection, DistancesAgreeWithSampling) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  auto random_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  constexpr int n = 60;
  for (int k = 0; k < 30; ++k) {
    const Triangle t = {random_vec(), random_vec(), random_vec()};
    const Vec3 p = 2 * random_vec(), q = 2 * random_vec();
    double sampled_point = INFINITY, sampled_segment = INFINITY, sampled_edges = INFINITY;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 x = t[0] + (t[1] - t[0]) * i / n + (t[2] - t[0]) * j / n;
        sampled_point = std::min(sampled_point, (x - p).norm());
        for (int s = 0; s <= 4 * n; ++s)
          sampled_segment = std::min(sampled_segment, (x - (p + (q - p) * s / (4 * n))).norm());
      }
    for (int i = 0; i <= 4 * n; ++i)
      for (int j = 0; j <= 4 * n; ++j)
        sampled_edges =
            std::min(sampled_edges,
                     (p + (q - p) * i / (4 * n) - (t[0] + (t[1] - t[0]) * j / (4 * n))).norm());
    const double d = point_triangle_distance(p, t);
    EXPECT_LE(d, sampled_point + 1e-12) << k;
    EXPECT_GE(d, sampled_point - 0.05) << k;
    const double ds = segment_triangle_distance(p, q, t);
    EXPECT_LE(ds, sampled_segment + 1e-12) << k;
    EXPECT_GE(ds, sampled_segment - 0.06) << k;
    const double de = segment_segment_distance(p, q, t[0], t[1]);
    EXPECT_LE(de, sampled_edges + 1e-12) << k;
    EXPECT_GE(de, sampled_edges - 0.04) << k;
  }
  EXPECT_DOUBLE_EQ(point_triangle_distance(Vec3(0.2, 0.2, 0.3), kFloor), 0.3);
  EXPECT_NEAR(point_triangle_distance(Vec3(2, 0, 0), kFloor), 1.0, 1e-15);
  EXPECT_NEAR(segment_segment_distance(Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0.5, -1, 0),
                                       Vec3(0.5, 1, 0)),
              1.0, 1e-15);
}

}  // namespace
}  // namespace shapectl::test
