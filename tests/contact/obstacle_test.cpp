// The obstacle shapes: geometry, orientation, closedness, and bad input named.
#include <shapectl/contact/obstacle.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <stdexcept>

namespace shapectl {
namespace {

// Each undirected edge's number of triangles.
std::map<std::array<int, 2>, int> edge_uses(const Obstacle& o) {
  std::map<std::array<int, 2>, int> uses;
  for (const auto& t : o.triangles)
    for (int k = 0; k < 3; ++k)
      ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  return uses;
}

TEST(MakeBox, IsEightCornersAndTwelveOutwardTrianglesWithEveryEdgeOnce) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()));
  T.pretranslate(Vec3(0.1, -0.2, 0.3));
  const Obstacle box = make_box("b", Vec3(0.2, 0.1, 0.05), T);
  EXPECT_EQ(box.shape, "box");
  ASSERT_EQ(box.points.size(), 8u);
  ASSERT_EQ(box.triangles.size(), 12u);
  EXPECT_EQ(box.radius, 0);
  EXPECT_FALSE(box.plane);
  for (const Vec3& p : box.points) {
    const Vec3 local = T.inverse() * p;
    EXPECT_NEAR(std::abs(local.x()), 0.1, 1e-12);
    EXPECT_NEAR(std::abs(local.y()), 0.05, 1e-12);
    EXPECT_NEAR(std::abs(local.z()), 0.025, 1e-12);
  }
  double area = 0;
  for (const auto& t : box.triangles) {
    const Vec3 n = (box.points[t[1]] - box.points[t[0]]).cross(box.points[t[2]] - box.points[t[0]]);
    const Vec3 centroid = (box.points[t[0]] + box.points[t[1]] + box.points[t[2]]) / 3;
    EXPECT_GT(n.dot(centroid - T.translation()), 0) << "a triangle faces inward";
    area += 0.5 * n.norm();
  }
  EXPECT_NEAR(area, 2 * (0.2 * 0.1 + 0.2 * 0.05 + 0.1 * 0.05), 1e-12);
  // Closed, and the edges are its triangles' edges, each once: 12 box edges + 6 diagonals.
  const auto uses = edge_uses(box);
  ASSERT_EQ(box.edges.size(), 18u);
  ASSERT_EQ(uses.size(), 18u);
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 2);
  for (const auto& e : box.edges)
    EXPECT_EQ(uses.count({std::min(e[0], e[1]), std::max(e[0], e[1])}), 1u);
}

TEST(MakePlane, NormalizesTheNormalAndKeepsNoPrimitives) {
  const Obstacle plane = make_plane("table", Vec3(0, 0, 0.7), Vec3(0, 0, 3));
  ASSERT_TRUE(plane.plane);
  EXPECT_NEAR(plane.plane->normal.z(), 1, 1e-15);
  EXPECT_TRUE(plane.points.empty() && plane.edges.empty() && plane.triangles.empty());
  EXPECT_THROW(make_plane("p", Vec3::Zero(), Vec3::Zero()), std::invalid_argument);
}

TEST(MakeSphereAndCapsule, AreInflatedPointsAndSegments) {
  const Obstacle sphere = make_sphere("s", Vec3(1, 2, 3), 0.05);
  EXPECT_EQ(sphere.points.size(), 1u);
  EXPECT_EQ(sphere.radius, 0.05);
  const Obstacle capsule = make_capsule("c", Vec3(0, 0, 0), Vec3(1, 0, 0), 0.02);
  EXPECT_EQ(capsule.points.size(), 2u);
  ASSERT_EQ(capsule.edges.size(), 1u);
  EXPECT_EQ(capsule.radius, 0.02);
  try {
    make_sphere("ball", Vec3::Zero(), -1);
    FAIL() << "a negative radius was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'ball'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos) << e.what();
  }
}

// A regular octahedron: 6 vertices, 8 outward triangles.
std::vector<std::array<int, 3>> octahedron_triangles() {
  return {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
}
std::vector<Vec3> octahedron_vertices() {
  return {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
}

TEST(MakeMeshObstacle, KeepsAClosedMeshWithEveryEdgeOnce) {
  const Obstacle mesh = make_mesh_obstacle("m", octahedron_vertices(), octahedron_triangles());
  EXPECT_EQ(mesh.shape, "mesh");
  EXPECT_EQ(mesh.points.size(), 6u);
  EXPECT_EQ(mesh.triangles.size(), 8u);
  EXPECT_EQ(mesh.edges.size(), 12u);
}

TEST(MakeMeshObstacle, RefusesAnOpenMeshNamingTheEdge) {
  auto triangles = octahedron_triangles();
  triangles.pop_back();  // {0, 3, 5} gone: edges 0-3, 3-5 and 0-5 are each in one triangle
  try {
    make_mesh_obstacle("fixture", octahedron_vertices(), triangles);
    FAIL() << "an open mesh was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'fixture'"), std::string::npos) << message;
    EXPECT_NE(message.find("not closed"), std::string::npos) << message;
    EXPECT_NE(message.find("edge 0-3"), std::string::npos) << message;
  }
  EXPECT_THROW(make_mesh_obstacle("m", octahedron_vertices(), {{0, 1, 9}}), std::invalid_argument);
}

}  // namespace
}  // namespace shapectl
