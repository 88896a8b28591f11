#include <shapectl/mesh/surface_mesher.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::TempDir;

// A 0.125 m cube (exact in float, for binary STL): corner i has bits (x, y, z) =
// (i & 1, i & 2, i & 4), outward quads.
const double side = 0.125;
Vec3 corner(int i) { return side * Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1); }
const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

std::string vertex_lines(const std::string& prefix) {
  std::ostringstream s;
  for (int i = 0; i < 8; ++i)
    s << prefix << corner(i).x() << " " << corner(i).y() << " " << corner(i).z() << "\n";
  return s.str();
}

// OBJ with quads in several index forms, texture/normal lines and comments.
std::string cube_obj() {
  std::string s = "# cube\no cube\n" + vertex_lines("v ") + "vt 0 0\nvn 0 0 1\ns off\n";
  s += "f 1/1/1 3/1/1 4/1/1 2/1/1\n";  // v/vt/vn
  s += "f 5//1 6//1 8//1 7//1\n";      // v//vn
  s += "f -8 -7 -3 -4\n";              // negative: 1 2 6 5
  s += "f 3 7 8\nf 3 8 4\n";           // a quad as two triangles
  s += "f 1 5 7 3\nf 2 4 8 6\n";
  return s;
}

std::string cube_off() {
  std::string s = "OFF\n# cube\n8 6 12\n" + vertex_lines("");
  for (const auto& q : quads)
    s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
         " " + std::to_string(q[3]) + "\n";
  return s;
}

// The cube's quads as triangles (0, 1, 2) and (0, 2, 3).
std::vector<std::array<int, 3>> cube_triangles() {
  std::vector<std::array<int, 3>> out;
  for (const auto& q : quads) {
    out.push_back({q[0], q[1], q[2]});
    out.push_back({q[0], q[2], q[3]});
  }
  return out;
}

std::string cube_ascii_stl() {
  std::ostringstream s;
  s << "solid cube\n";
  for (const auto& t : cube_triangles()) {
    s << "  facet normal 0 0 0\n    outer loop\n";
    for (int v : t)
      s << "      vertex " << corner(v).x() << " " << corner(v).y() << " " << corner(v).z() << "\n";
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid cube\n";
  return s.str();
}

std::string cube_binary_stl() {
  std::string s(80, ' ');
  auto put = [&s](const void* data, std::size_t size) {
    s.append(static_cast<const char*>(data), size);  // little-endian host assumed
  };
  const std::uint32_t count = 12;
  put(&count, 4);
  for (const auto& t : cube_triangles()) {
    const float normal[3] = {0, 0, 0};
    put(normal, 12);
    for (int v : t) {
      const float x[3] = {float(corner(v).x()), float(corner(v).y()), float(corner(v).z())};
      put(x, 12);
    }
    const std::uint16_t attribute = 0;
    put(&attribute, 2);
  }
  return s;
}

// The cube's volume, with the surface's vertices first and in order.
void expect_meshed_cube(const TetMesh& mesh, const TriangleSurface& surface) {
  EXPECT_NEAR(mesh.total_volume(), side * side * side, 1e-15);
  ASSERT_EQ(surface.vertices.size(), 8u);
  ASSERT_GE(mesh.node_count(), 8);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(mesh.rest_positions()[i], surface.vertices[i]) << i;
}

std::string error_of(const std::filesystem::path& file, const SurfaceMeshOptions& options = {}) {
  try {
    mesh_surface(file, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SurfaceMesher, TetrahedralizesAnObjCubeKeepingVerticesFirst) {
  TempDir dir;
  const auto file = dir.write("cube.obj", cube_obj());
  const TriangleSurface surface = read_surface(file);
  ASSERT_EQ(surface.vertices.size(), 8u);
  EXPECT_EQ(surface.triangles.size(), 12u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(surface.vertices[i], corner(i));
  expect_meshed_cube(mesh_surface(file), surface);
}

TEST(SurfaceMesher, TetrahedralizesOffAndStlCubes) {
  TempDir dir;
  const auto off = dir.write("cube.off", cube_off());
  for (int i = 0; i < 8; ++i) EXPECT_EQ(read_surface(off).vertices[i], corner(i));
  expect_meshed_cube(mesh_surface(off), read_surface(off));
  // STL lists triangles only: vertices come in order of first use.
  const std::vector<int> first_use = {0, 2, 3, 1, 4, 5, 7, 6};
  for (const auto& stl :
       {dir.write("cube.stl", cube_ascii_stl()), dir.write("binary.STL", cube_binary_stl())}) {
    const TriangleSurface surface = read_surface(stl);
    ASSERT_EQ(surface.vertices.size(), 8u);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(surface.vertices[i], corner(first_use[i]));
    expect_meshed_cube(mesh_surface(stl), surface);
  }
}

TEST(SurfaceMesher, MaxVolumeRefines) {
  TempDir dir;
  const auto file = dir.write("cube.obj", cube_obj());
  const TetMesh coarse = mesh_surface(file, {.max_radius_edge_ratio = 0});
  const TetMesh fine = mesh_surface(file, {.max_tet_volume = 1e-6});
  EXPECT_GT(fine.tet_count(), 2 * coarse.tet_count());
  // TetGen's final smoothing may leave a tet slightly above the bound.
  EXPECT_GE(fine.tet_count(), side * side * side / 1e-6);
  for (const auto& t : fine.tets()) EXPECT_LE(t.volume, 1.5e-6);
  expect_meshed_cube(fine, read_surface(file));
}

TEST(SurfaceMesher, KeepSurfaceAddsNoBoundaryPoints) {
  TempDir dir;
  const TetMesh mesh = mesh_surface(dir.write("cube.obj", cube_obj()),
                                    {.max_radius_edge_ratio = 0, .keep_surface = true});
  EXPECT_EQ(mesh.surface_triangles().size(), 12u);
}

TEST(SurfaceMesher, OpenSurfaceIsRefused) {
  TempDir dir;
  std::string obj = cube_obj();
  obj.erase(obj.find("f 2 4 8 6\n"));
  const auto file = dir.write("open.obj", obj);
  EXPECT_EQ(error_of(file), file.string() +
                                ": the surface is not closed: edge (0.125, 0, 0)-(0.125, 0.125, 0) "
                                "belongs to 1 triangle, expected 2");
}

TEST(SurfaceMesher, SelfIntersectingSurfaceIsRefusedWithTetgensReason) {
  // Two closed tetrahedra, one poking through a face of the other.
  TempDir dir;
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
      "v 0.2 0.2 0.2\nv 1.2 0.2 0.2\nv 0.2 1.2 0.2\nv 0.2 0.2 1.2\n"
      "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
      "f 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n";
  const auto file = dir.write("crossing.obj", obj);
  EXPECT_EQ(error_of(file), file.string() + ": TetGen failed: the surface intersects itself");
}

TEST(SurfaceMesher, BadSurfaceFilesNameFileAndLine) {
  TempDir dir;
  auto file = dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(file),
            file.string() + ":3: face: vertex index 3 out of range (2 vertices so far)");
  file = dir.write("word.obj", "v 0 zero 0\n");
  EXPECT_EQ(error_of(file), file.string() + ":1: expected a number for y, got 'zero'");
  file = dir.write("twice.obj", "v 0 0 0\nv 1 0 0\nv 0 0 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(file), file.string() + ":4: face: uses the same vertex twice");
  file = dir.write("empty.obj", "# nothing\n");
  EXPECT_EQ(error_of(file), file.string() + ": no faces");
  file = dir.write("short.off", "OFF\n8 6 12\n0 0 0\n");
  EXPECT_EQ(error_of(file), file.string() + ":3: file ends early: expected vertex 1 of 8");
  file = dir.write("facet.stl",
                   "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                   "vertex 1 0 0\nendloop\nendfacet\nendsolid\n");
  EXPECT_EQ(error_of(file), file.string() + ":7: facet: expected 3 vertices, found 2");
  file = dir.write("junk.stl", "not an stl");
  EXPECT_EQ(error_of(file), file.string() +
                                ": neither ASCII STL (starting with 'solid') nor binary STL (84 "
                                "+ 50 bytes per triangle; this file has 10 bytes)");
  file = dir.write("cube.ply", "ply\n");
  EXPECT_EQ(error_of(file),
            file.string() + ": unknown surface format '.ply' (supported: .obj, .stl, .off)");
  EXPECT_EQ(error_of(dir.path() / "absent.obj"),
            (dir.path() / "absent.obj").string() + ": file not found");
}

TEST(SurfaceMesher, BadOptionsAreRefused) {
  TempDir dir;
  const auto file = dir.write("cube.obj", cube_obj());
  EXPECT_EQ(error_of(file, {.max_radius_edge_ratio = 0.5}),
            file.string() + ": max_radius_edge_ratio: expected 0 (off) or a ratio >= 1, got 0.5");
  EXPECT_EQ(error_of(file, {.max_tet_volume = -1}),
            file.string() +
                ": max_tet_volume: expected 0 (no bound) or a positive volume in m^3, got -1");
}

}  // namespace
}  // namespace shapectl
