#include <shapectl/io/surface_writer.hpp>

#include <gtest/gtest.h>

#include <stdexcept>

namespace shapectl {
namespace {

// One tet's four faces over nodes 0..3, and a fifth node no face uses.
Positions five_positions() {
  Positions x(15);
  x << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1, 1.0 / 3, 0.5, 0.5;
  return x;
}
const std::vector<std::array<int, 3>> tet_faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

TEST(SurfaceWriter, FormatComesFromTheExtensionInAnyCase) {
  EXPECT_EQ(surface_format("a/b.ply"), SurfaceFormat::Ply);
  EXPECT_EQ(surface_format("b.OBJ"), SurfaceFormat::Obj);
  EXPECT_EQ(surface_format("b.stl"), std::nullopt);
  EXPECT_EQ(surface_format("ply"), std::nullopt);
}

TEST(SurfaceWriter, PlyHasEveryNodeAndEachTriangle) {
  const std::string text = surface_text(SurfaceFormat::Ply, five_positions(), tet_faces);
  EXPECT_EQ(text.rfind("ply\nformat ascii 1.0\n", 0), 0u);
  EXPECT_NE(text.find("element vertex 5\n"), std::string::npos);
  EXPECT_NE(text.find("element face 4\n"), std::string::npos);
  EXPECT_NE(text.find("end_header\n0 0 0\n0.10000000000000001 0 0\n"), std::string::npos);
  EXPECT_NE(text.find("\n0.33333333333333331 0.5 0.5\n3 0 2 1\n"), std::string::npos);
  EXPECT_TRUE(text.ends_with("3 1 2 3\n"));
}

TEST(SurfaceWriter, ObjCountsVerticesFromOne) {
  const std::string text = surface_text(SurfaceFormat::Obj, five_positions(), tet_faces);
  EXPECT_NE(text.find("\nv 0 0 0\n"), std::string::npos);
  EXPECT_NE(text.find("\nf 1 3 2\n"), std::string::npos);
  EXPECT_TRUE(text.ends_with("f 2 3 4\n"));
}

TEST(SurfaceWriter, MismatchedInputIsRefused) {
  EXPECT_THROW(surface_text(SurfaceFormat::Ply, five_positions(), {{0, 1, 5}}),
               std::invalid_argument);
  EXPECT_THROW(surface_text(SurfaceFormat::Obj, Positions::Zero(4), {}), std::invalid_argument);
  Positions bad = five_positions();
  bad[4] = NAN;
  EXPECT_THROW(surface_text(SurfaceFormat::Obj, bad, tet_faces), std::invalid_argument);
}

}  // namespace
}  // namespace shapectl
