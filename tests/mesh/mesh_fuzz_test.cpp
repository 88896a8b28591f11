// Mutated mesh files (MSH 2.2 and 4.1, TetGen, OBJ, STL ASCII and binary, OFF), generated from
// a small valid box: each loads or throws InputError.
#include <shapectl/mesh/load_mesh.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include <shapectl/mesh/box_mesh.hpp>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const TetMesh& box() {
  static const TetMesh mesh = make_box_mesh({0.2, 0.1, 0.1}, {2, 1, 1});
  return mesh;
}

std::string msh22() {
  std::ostringstream s;
  s.precision(17);
  s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << box().node_count() << "\n";
  for (int i = 0; i < box().node_count(); ++i)
    s << i + 1 << " " << box().rest_positions()[i].transpose() << "\n";
  s << "$EndNodes\n$Elements\n" << box().tet_count() << "\n";
  for (int e = 0; e < box().tet_count(); ++e) {
    s << e + 1 << " 4 2 0 1";
    for (int a : box().tets()[e].nodes) s << " " << a + 1;
    s << "\n";
  }
  return s.str() + "$EndElements\n";
}

std::string msh41() {
  std::ostringstream s;
  s.precision(17);
  const int n = box().node_count(), m = box().tet_count();
  s << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 " << n << " 1 " << n << "\n3 1 0 " << n
    << "\n";
  for (int i = 0; i < n; ++i) s << i + 1 << "\n";
  for (int i = 0; i < n; ++i) s << box().rest_positions()[i].transpose() << "\n";
  s << "$EndNodes\n$Elements\n1 " << m << " 1 " << m << "\n3 1 4 " << m << "\n";
  for (int e = 0; e < m; ++e) {
    s << e + 1;
    for (int a : box().tets()[e].nodes) s << " " << a + 1;
    s << "\n";
  }
  return s.str() + "$EndElements\n";
}

std::string tetgen_node() {
  std::ostringstream s;
  s.precision(17);
  s << box().node_count() << " 3 0 0\n";
  for (int i = 0; i < box().node_count(); ++i)
    s << i << " " << box().rest_positions()[i].transpose() << "\n";
  return s.str();
}

std::string tetgen_ele() {
  std::ostringstream s;
  s << box().tet_count() << " 4 0\n";
  for (int e = 0; e < box().tet_count(); ++e) {
    s << e;
    for (int a : box().tets()[e].nodes) s << " " << a;
    s << "\n";
  }
  return s.str();
}

std::string obj() {
  std::ostringstream s;
  for (const auto& x : box().rest_positions()) s << "v " << x.transpose() << "\n";
  for (const auto& t : box().surface_triangles())
    s << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return s.str();
}

std::string off() {
  const auto triangles = box().surface_triangles();
  std::ostringstream s;
  s << "OFF\n" << box().node_count() << " " << triangles.size() << " 0\n";
  for (const auto& x : box().rest_positions()) s << x.transpose() << "\n";
  for (const auto& t : triangles) s << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return s.str();
}

std::string ascii_stl() {
  std::ostringstream s;
  s << "solid box\n";
  for (const auto& t : box().surface_triangles()) {
    s << "facet normal 0 0 0\nouter loop\n";
    for (int v : t) s << "vertex " << box().rest_positions()[v].transpose() << "\n";
    s << "endloop\nendfacet\n";
  }
  return s.str() + "endsolid box\n";
}

std::string binary_stl() {
  const auto triangles = box().surface_triangles();
  std::string s(80, ' ');
  auto put = [&](const void* p, std::size_t n) { s.append(static_cast<const char*>(p), n); };
  const std::uint32_t count = static_cast<std::uint32_t>(triangles.size());
  put(&count, 4);  // little-endian hosts (x86, ARM)
  for (const auto& t : triangles) {
    const float normal[3] = {0, 0, 0};
    put(normal, 12);
    for (int v : t) {
      const float x[3] = {float(box().rest_positions()[v].x()),
                          float(box().rest_positions()[v].y()),
                          float(box().rest_positions()[v].z())};
      put(x, 12);
    }
    const std::uint16_t attribute = 0;
    put(&attribute, 2);
  }
  return s;
}

const test::TextMutator kMeshMutator({"nan",
                                      "inf",
                                      "-inf",
                                      "1e999",
                                      "-1e308",
                                      "1e-400",
                                      "-1",
                                      "0",
                                      "999999999",
                                      "2147483648",
                                      "99999999999999999999",
                                      "x",
                                      "\n",
                                      " ",
                                      "$Nodes\n",
                                      "$EndNodes\n",
                                      "$Elements\n",
                                      "$EndElements\n",
                                      "$Foo\n",
                                      "4.1",
                                      "v 0 0 0\n",
                                      "f 1 1 1\n",
                                      "f -99 1 2\n",
                                      "3 0 1\n",
                                      "facet\n",
                                      "vertex 1 2 3\n",
                                      "endfacet\n",
                                      "# comment\n",
                                      "+",
                                      "1/2/3",
                                      "\0"});

// `cases` mutations of `seed`, each written as `name` and loaded.
test::FuzzCounts fuzz_format(const std::string& name, const std::string& seed, int cases,
                             unsigned rng_seed, const std::string& companion_name = "",
                             const std::string& companion = "",
                             const SurfaceMeshOptions& options = {.max_radius_edge_ratio = 0}) {
  const test::TempDir dir;
  if (!companion_name.empty()) dir.write(companion_name, companion);
  return test::fuzz_parser({seed}, kMeshMutator, cases, rng_seed, [&](const std::string& text) {
    const auto file = dir.path() / name;
    std::ofstream(file, std::ios::binary) << text;
    load_mesh(file, options);
  });
}

TEST(MeshFuzz, ValidSeedsLoad) {
  const test::TempDir dir;
  EXPECT_EQ(load_mesh(dir.write("a.msh", msh22())).tet_count(), 12);
  EXPECT_EQ(load_mesh(dir.write("b.msh", msh41())).tet_count(), 12);
  dir.write("c.node", tetgen_node());
  EXPECT_EQ(load_mesh(dir.write("c.ele", tetgen_ele())).tet_count(), 12);
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"d.obj", obj()},
                                   {"e.off", off()},
                                   {"f.stl", ascii_stl()},
                                   {"g.stl", binary_stl()}})
    EXPECT_NEAR(load_mesh(dir.write(name, text), {.max_radius_edge_ratio = 0}).total_volume(),
                0.002, 1e-9)
        << name;
}

TEST(MeshFuzz, MutatedVolumeMeshesLoadOrAreInputErrors) {
  for (const auto& [name, seed, companion_name, companion] :
       {std::tuple<std::string, std::string, std::string, std::string>{"m.msh", msh22(), "", ""},
        {"m.msh", msh41(), "", ""},
        {"t.node", tetgen_node(), "t.ele", tetgen_ele()},
        {"t.ele", tetgen_ele(), "t.node", tetgen_node()}}) {
    const test::FuzzCounts counts = fuzz_format(name, seed, 600, 7, companion_name, companion);
    EXPECT_GT(counts.refused, 100) << name;
    EXPECT_GT(counts.parsed, 10) << name;
  }
}

TEST(MeshFuzz, MutatedSurfacesLoadOrAreInputErrors) {
  for (const auto& [name, seed] : {std::pair<std::string, std::string>{"s.obj", obj()},
                                   {"s.off", off()},
                                   {"s.stl", ascii_stl()},
                                   {"b.stl", binary_stl()}}) {
    const test::FuzzCounts counts = fuzz_format(name, seed, 300, 11, "", "");
    EXPECT_GT(counts.refused, 100) << name;
    EXPECT_GT(counts.parsed, 10) << name;
  }
}

TEST(MeshFuzz, MutatedSurfacesRefinedByTetGenLoadOrAreInputErrors) {
  // Quality and volume refinement on whatever survives reading: bounded by the tet budget.
  const test::FuzzCounts counts =
      fuzz_format("r.obj", obj(), 300, 13, "", "",
                  {.max_radius_edge_ratio = 1.2, .max_tet_volume = 1e-5});
  EXPECT_GT(counts.refused, 50);
  EXPECT_GT(counts.parsed, 10);
}

}  // namespace
}  // namespace shapectl
