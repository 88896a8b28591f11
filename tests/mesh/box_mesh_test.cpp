#include <shapectl/mesh/box_mesh.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <shapectl/io/input_error.hpp>

namespace shapectl {
namespace {

TEST(BoxMesh, DefaultBarHasExpectedCounts) {
  const TetMesh mesh = make_box_mesh({0.32, 0.03, 0.03}, {16, 4, 4});
  EXPECT_EQ(mesh.node_count(), 17 * 5 * 5);
  EXPECT_EQ(mesh.tet_count(), 1536);
  EXPECT_TRUE(mesh.isolated_nodes().empty());
}

TEST(BoxMesh, SpansTheBoxCentredAtTheOrigin) {
  const TetMesh mesh = make_box_mesh({0.32, 0.03, 0.02}, {16, 4, 3});
  EXPECT_TRUE(mesh.bounds_min().isApprox(Vec3(-0.16, -0.015, -0.01)));
  EXPECT_TRUE(mesh.bounds_max().isApprox(Vec3(0.16, 0.015, 0.01)));
  EXPECT_NEAR(mesh.total_volume(), 0.32 * 0.03 * 0.02, 1e-15);
}

TEST(BoxMesh, NodeIndexFollowsGridOrder) {
  const int nx = 3, ny = 2, nz = 4;
  const TetMesh mesh = make_box_mesh({3, 2, 4}, {nx, ny, nz});
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const Vec3 expected(i - 1.5, j - 1.0, k - 2.0);
        EXPECT_TRUE(mesh.rest_positions()[i + (nx + 1) * (j + (ny + 1) * k)].isApprox(expected));
      }
}

TEST(BoxMesh, EveryTetIsPositiveAndOfEqualVolume) {
  const TetMesh mesh = make_box_mesh({0.6, 0.4, 0.5}, {3, 2, 5});
  const double cell_volume = 0.2 * 0.2 * 0.1;
  for (const auto& t : mesh.tets()) EXPECT_NEAR(t.volume, cell_volume / 6, 1e-15);
}

TEST(BoxMesh, TetsConformAcrossCells) {
  // Every interior face shared by exactly two tets: only the box's own faces remain, 2 per quad.
  const int nx = 5, ny = 3, nz = 2;
  const TetMesh mesh = make_box_mesh({1, 1, 1}, {nx, ny, nz});
  EXPECT_EQ(mesh.surface_triangles().size(), 2u * 2u * (nx * ny + ny * nz + nx * nz));
}

TEST(BoxMesh, RejectsBadSizeAndCells) {
  const double inf = std::numeric_limits<double>::infinity();
  auto message = [](auto make) {
    try {
      make();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([] {
              make_box_mesh({0.1, 0, 0.1}, {1, 1, 1});
            }),
            "box mesh: size.y: expected a positive finite length, got 0");
  EXPECT_EQ(message([&] {
              make_box_mesh({inf, 1, 1}, {1, 1, 1});
            }),
            "box mesh: size.x: expected a positive finite length, got inf");
  EXPECT_EQ(message([] {
              make_box_mesh({1, 1, std::nan("")}, {1, 1, 1});
            }),
            "box mesh: size.z: expected a positive finite length, got nan");
  EXPECT_EQ(message([] {
              make_box_mesh({1, 1, 1}, {1, 1, 0});
            }),
            "box mesh: cells.z: expected at least 1 cell, got 0");
}

}  // namespace
}  // namespace shapectl
