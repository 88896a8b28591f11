// Mesh inputs with bounded cost: tet budgets for boxes and TetGen, counts checked from headers,
// and files that are not regular refused.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <string>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/mesh/load_mesh.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/surface_mesher.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

std::string error_of(const std::function<void()>& f) { return test::input_error_of(f); }

// The unit cube as 12 outward triangles.
TriangleSurface unit_cube() {
  TriangleSurface s;
  for (int i = 0; i < 8; ++i) s.vertices.push_back(Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  return s;
}

TEST(MeshLimits, BoxCellProductIsBounded) {
  EXPECT_EQ(error_of([] {
              make_box_mesh({1, 1, 1}, {1000, 1000, 1000});
            }),
            "box mesh: cells: expected at most 1000000 tetrahedra (6 per cell), got 6000000000");
  EXPECT_EQ(make_box_mesh({1, 1, 1}, {1000, 1, 1}).tet_count(), 6000);
}

TEST(MeshLimits, TinyMaxTetVolumeIsRefusedBeforeTetGenRuns) {
  SurfaceMeshOptions options{.max_tet_volume = 1e-12};
  EXPECT_EQ(error_of([&] { tetrahedralize_surface(unit_cube(), options, "cube.obj"); }),
            "cube.obj: max_tet_volume: expected 0 (no bound) or at least 5e-06 m^3 (the surface "
            "cube.obj encloses 1 m^3; at most 200000 times smaller), got 1e-12");
  options.origin_file = "scene.json";
  options.origin_path = "object.mesh";
  EXPECT_EQ(
      error_of([&] { tetrahedralize_surface(unit_cube(), options, "cube.obj"); })
          .rfind(
              "scene.json: object.mesh.max_tet_volume: expected 0 (no bound) or at least 5e-06 m^3",
              0),
      0u);
  // At the budget TetGen runs and meets the bound.
  options.max_tet_volume = 0.01;
  const TetMesh mesh = tetrahedralize_surface(unit_cube(), options, "cube.obj");
  EXPECT_GE(mesh.tet_count(), 100);
  for (const auto& t : mesh.tets()) EXPECT_LE(t.volume, 0.01 * (1 + 1e-9));
}

TEST(MeshLimits, HugeSurfaceCoordinatesAreRefusedBeforeTetGen) {
  TriangleSurface cube = unit_cube();
  cube.vertices[7] = Vec3(1e300, 1, 1);
  EXPECT_EQ(
      error_of([&] { tetrahedralize_surface(cube, {}, "cube.obj"); }),
      "cube.obj: vertex 7: expected coordinates within 1e6 m of the origin, got (1e+300, 1, 1)");
}

TEST(MeshLimits, CountsInHeadersAreBounded) {
  const test::TempDir dir;
  const auto node = dir.write("big.node", "1000001 3 0 0\n0 0 0 0\n");
  EXPECT_EQ(error_of([&] { load_mesh(node); }),
            node.string() + ":1: header: point count must be 0..1000000, got 1000001");
}

TEST(MeshLimits, FifoMeshFileIsRefusedWithoutWaiting) {
  const test::TempDir dir;
  for (const std::string name : {"bar.msh", "bar.node", "bar.obj", "bar.stl", "bar.off"}) {
    const auto fifo = dir.path() / name;
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_EQ(error_of([&] { load_mesh(fifo); }), fifo.string() + ": not a regular file (a FIFO)");
  }
}

}  // namespace
}  // namespace shapectl
