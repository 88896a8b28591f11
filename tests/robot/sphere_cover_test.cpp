// Sphere covers of collision primitives: every sampled point of a primitive is inside a sphere.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/robot/sphere_cover.hpp>

namespace shapectl {
namespace {

// Distance by which p is outside every sphere (≤ 0: covered).
double uncovered(const std::vector<CoverSphere>& spheres, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : spheres) best = std::min(best, (p - s.center).norm() - s.radius);
  return best;
}

Vec3 uniform_in_box(const Vec3& size, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  return Vec3(u(rng), u(rng), u(rng)).cwiseProduct(size);
}

TEST(SphereCover, BoxCoverContainsSampledPointsAndEveryCorner) {
  std::mt19937 rng(7);
  for (const Vec3& size :
       {Vec3(0.1, 0.1, 0.1), Vec3(0.3, 0.03, 0.05), Vec3(0.5, 0.4, 0.01), Vec3(2.0, 0.02, 0.02)}) {
    const auto spheres = cover_box(size);
    ASSERT_FALSE(spheres.empty());
    EXPECT_LE(spheres.size(), 64u) << size.transpose();
    for (int k = 0; k < 2000; ++k)
      EXPECT_LE(uncovered(spheres, uniform_in_box(size, rng)), 0) << size.transpose();
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner =
          0.5 * Vec3(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1).cwiseProduct(size);
      EXPECT_LE(uncovered(spheres, corner), 0) << size.transpose() << " corner " << c;
    }
  }
}

TEST(SphereCover, BoxCoverIsTightForAThinBar) {
  // A bar 10 × its section: a chain of spheres little larger than the section.
  const auto spheres = cover_box(Vec3(0.3, 0.03, 0.03));
  EXPECT_EQ(spheres.size(), 8u);
  for (const auto& s : spheres) EXPECT_LT(s.radius, 0.035);
}

TEST(SphereCover, CylinderCoverContainsSampledPointsOfItsRimAndVolume) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& [radius, length] :
       {std::pair{0.03, 0.3}, std::pair{0.1, 0.02}, std::pair{0.05, 0.05}}) {
    const auto spheres = cover_cylinder(radius, length);
    EXPECT_LE(spheres.size(), static_cast<std::size_t>(max_cover_cells_per_axis));
    for (int k = 0; k < 2000; ++k) {
      const double angle = 2 * M_PI * u(rng);
      // Half the samples on the rim of an end face, where a cover is most likely to miss.
      const double r = k % 2 ? radius : radius * std::sqrt(u(rng));
      const double z = k % 2 ? (u(rng) < 0.5 ? -0.5 : 0.5) * length : (u(rng) - 0.5) * length;
      EXPECT_LE(uncovered(spheres, Vec3(r * std::cos(angle), r * std::sin(angle), z)), 0)
          << radius << " " << length;
    }
  }
}

TEST(SphereCover, ShapeCoverIsPlacedInTheLinkFrame) {
  std::mt19937 rng(3);
  Shape box;
  box.kind = Shape::Kind::Box;
  box.box_size = Vec3(0.2, 0.05, 0.04);
  box.T_link_shape.translation() = Vec3(0.1, -0.2, 0.3);
  box.T_link_shape.linear() = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Shape sphere;
  sphere.kind = Shape::Kind::Sphere;
  sphere.radius = 0.04;
  sphere.T_link_shape.translation() = Vec3(0, 0.5, 0);
  const auto box_spheres = cover_shape(box);
  const auto sphere_spheres = cover_shape(sphere);
  ASSERT_EQ(sphere_spheres.size(), 1u);
  EXPECT_NEAR((sphere_spheres[0].center - Vec3(0, 0.5, 0)).norm(), 0, 1e-15);
  EXPECT_EQ(sphere_spheres[0].radius, 0.04);
  for (int k = 0; k < 1000; ++k)
    EXPECT_LE(uncovered(box_spheres, box.T_link_shape * uniform_in_box(box.box_size, rng)), 0);
  // The cover is not where the unplaced box would be.
  EXPECT_GT(uncovered(box_spheres, Vec3::Zero()), 0);
}

// A closed octahedron with half-axes a: convex, so convex combinations of its vertices are inside.
void octahedron(const Vec3& a, std::vector<Vec3>& v, std::vector<std::array<int, 3>>& t) {
  v = {Vec3(a.x(), 0, 0),  Vec3(-a.x(), 0, 0), Vec3(0, a.y(), 0),
       Vec3(0, -a.y(), 0), Vec3(0, 0, a.z()),  Vec3(0, 0, -a.z())};
  t = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
}

TEST(SphereCover, TriangleMeshCoverContainsItsSurfaceAndInterior) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  octahedron(Vec3(0.2, 0.1, 0.1), v, t);
  const auto spheres = cover_triangle_mesh(v, t);
  ASSERT_FALSE(spheres.empty());
  EXPECT_LE(spheres.size(), 64u);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 3000; ++k) {
    // On a triangle (uniform barycentric) ...
    const auto& tri = t[static_cast<std::size_t>(k) % t.size()];
    double b1 = u(rng), b2 = u(rng);
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    EXPECT_LE(uncovered(spheres,
                        v[tri[0]] + b1 * (v[tri[1]] - v[tri[0]]) + b2 * (v[tri[2]] - v[tri[0]])),
              0);
    // ... and inside.
    Eigen::Matrix<double, 6, 1> w;
    for (int i = 0; i < 6; ++i) w[i] = -std::log(u(rng) + 1e-300);
    Vec3 p = Vec3::Zero();
    for (int i = 0; i < 6; ++i) p += w[i] / w.sum() * v[static_cast<std::size_t>(i)];
    EXPECT_LE(uncovered(spheres, p), 0);
  }
}

TEST(SphereCover, OpenMeshCoverContainsItsTriangles) {
  const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(0.3, 0, 0), Vec3(0, 0.2, 0.1)};
  const auto spheres = cover_triangle_mesh(v, {{0, 1, 2}});
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 1000; ++k) {
    double b1 = u(rng), b2 = u(rng);
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    EXPECT_LE(uncovered(spheres, v[0] + b1 * (v[1] - v[0]) + b2 * (v[2] - v[0])), 0);
  }
  EXPECT_TRUE(cover_triangle_mesh(v, {}).empty());
}

}  // namespace
}  // namespace shapectl
