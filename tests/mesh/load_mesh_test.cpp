#include <shapectl/mesh/load_mesh.hpp>

#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::TempDir;

const char* tet_msh =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
    "$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n";

TEST(LoadMesh, DispatchesByExtensionIgnoringCase) {
  TempDir dir;
  EXPECT_EQ(load_mesh(dir.write("tet.MSH", tet_msh)).tet_count(), 1);
  dir.write("tet.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
  dir.write("tet.ele", "1 4 0\n0 0 1 2 3\n");
  EXPECT_EQ(load_mesh(dir.path() / "tet.ele").tet_count(), 1);
  EXPECT_EQ(load_mesh(dir.path() / "tet.node").tet_count(), 1);
  const auto obj =
      dir.write("tet.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  EXPECT_NEAR(load_mesh(obj, {.max_radius_edge_ratio = 0}).total_volume(), 1.0 / 6, 1e-15);
}

TEST(LoadMesh, UnknownExtensionNamesTheSupportedOnes) {
  TempDir dir;
  const auto file = dir.write("bar.vtk", "");
  try {
    load_mesh(file);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              file.string() +
                  ": unknown mesh format '.vtk' (supported: .msh, .node/.ele, and "
                  "surfaces .obj, .stl, .off)");
  }
}

}  // namespace
}  // namespace shapectl
