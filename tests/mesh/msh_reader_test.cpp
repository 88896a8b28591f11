#include <shapectl/mesh/msh_reader.hpp>

#include <gtest/gtest.h>

#include <random>
#include <string>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::TempDir;

// The unit cube as 6 tets; node i gets the non-contiguous tag 100 - 7 i, listed in index order.
const TetMesh cube = make_box_mesh({1, 1, 1}, {1, 1, 1});
long long tag_of(int node) { return 100 - 7 * node; }

std::string node_line(int i) {
  const Vec3& x = cube.rest_positions()[i];
  return std::to_string(tag_of(i)) + " " + std::to_string(x.x()) + " " + std::to_string(x.y()) +
         " " + std::to_string(x.z()) + "\n";
}

// "x y z" of node i, as in an MSH 4.1 node block.
std::string coordinates_line(int i) { return node_line(i).substr(node_line(i).find(' ') + 1); }

// " t0 t1 t2 t3": the tags of a tet's nodes.
std::string node_tags(const std::array<int, 4>& nodes) {
  std::string s;
  for (int n : nodes) {
    s += ' ';
    s += std::to_string(tag_of(n));
  }
  return s;
}
std::string tet_nodes(int e) { return node_tags(cube.tets()[e].nodes); }

// MSH 2.2 with points, lines, a triangle and a 10-node tet around the linear tets.
std::string msh22() {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  s += "$PhysicalNames\n1\n3 1 \"foam\"\n$EndPhysicalNames\n";
  s += "$Nodes\n8\n";
  for (int i = 0; i < 8; ++i) s += node_line(i);
  s += "$EndNodes\n$Elements\n10\n";
  s += "1 15 2 0 1 100\n2 1 2 0 1 100 93\n3 2 2 0 1 100 93 86\n";
  for (int e = 0; e < 6; ++e) s += std::to_string(10 + e) + " 4 2 1 1" + tet_nodes(e) + "\n";
  s += "20 11 2 1 1 100 93 86 79 72 65 58 51 100 93\n";
  s += "$EndElements\n";
  return s;
}

// MSH 4.1 with entities, two node blocks (one parametric) and mixed element blocks.
std::string msh41() {
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  s += "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  s += "$Nodes\n2 8 51 100\n";
  s += "2 1 0 3\n";  // a surface block
  for (int i = 0; i < 3; ++i) s += std::to_string(tag_of(i)) + "\n";
  for (int i = 0; i < 3; ++i) s += coordinates_line(i);
  s += "3 1 0 5\n";  // a volume block
  for (int i = 3; i < 8; ++i) s += std::to_string(tag_of(i)) + "\n";
  for (int i = 3; i < 8; ++i) s += coordinates_line(i);
  s += "$EndNodes\n$Elements\n2 7 1 7\n";
  s += "2 1 2 1\n1 100 93 86\n";
  s += "3 1 4 6\n";
  for (int e = 0; e < 6; ++e) s += std::to_string(2 + e) + tet_nodes(e) + "\n";
  s += "$EndElements\n";
  return s;
}

std::string replaced(std::string text, const std::string& from, const std::string& to);

// The surface block of msh41() marked parametric, with (u, v) after each x y z.
std::string msh41_with_parametric() {
  std::string s = replaced(msh41(), "2 1 0 3\n", "2 1 1 3\n");
  for (int i = 0; i < 3; ++i) {
    const std::string line = coordinates_line(i);
    s = replaced(s, line, line.substr(0, line.size() - 1) + " 0.5 0.25\n");
  }
  return s;
}

// Replaces the first occurrence of `from` in `text`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// 1-based line of the first occurrence of `needle`.
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_msh(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

void expect_same_as_cube(const TetMesh& mesh) {
  ASSERT_EQ(mesh.node_count(), 8);
  ASSERT_EQ(mesh.tet_count(), 6);
  for (int i = 0; i < 8; ++i)
    EXPECT_TRUE(mesh.rest_positions()[i].isApprox(cube.rest_positions()[i])) << i;
  for (int e = 0; e < 6; ++e) EXPECT_EQ(mesh.tets()[e].nodes, cube.tets()[e].nodes);
  EXPECT_NEAR(mesh.total_volume(), 1.0, 1e-12);
}

TEST(MshReader, Reads22KeepingNodeOrderAndIgnoringOtherElements) {
  TempDir dir;
  expect_same_as_cube(read_msh(dir.write("cube.msh", msh22())));
}

TEST(MshReader, Reads41KeepingNodeOrderAndIgnoringOtherElements) {
  TempDir dir;
  expect_same_as_cube(read_msh(dir.write("cube.msh", msh41())));
}

TEST(MshReader, Reads41ParametricNodes) {
  TempDir dir;
  expect_same_as_cube(read_msh(dir.write("cube.msh", msh41_with_parametric())));
}

TEST(MshReader, ToleratesWindowsLineEndings) {
  TempDir dir;
  std::string text;
  for (char c : msh22()) text += c == '\n' ? std::string("\r\n") : std::string(1, c);
  expect_same_as_cube(read_msh(dir.write("cube.msh", text)));
}

TEST(MshReader, MissingFileIsNamed) {
  TempDir dir;
  const auto file = dir.path() / "absent.msh";
  EXPECT_EQ(error_of(file), file.string() + ": file not found");
}

TEST(MshReader, TruncatedFileNamesTheLastLine) {
  TempDir dir;
  const std::string full = msh22();
  const std::string text = full.substr(0, full.find("12 4 2"));
  const auto file = dir.write("cut.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "11 4 2")) +
                                ": file ends early: expected element 6 of 10 (count on line " +
                                std::to_string(line_of(text, "10\n1 15")) + ")");
}

TEST(MshReader, WrongNodeCountsAreReported) {
  TempDir dir;
  const std::string too_many = replaced(msh22(), "$Nodes\n8\n", "$Nodes\n9\n");
  auto file = dir.write("many.msh", too_many);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(too_many, "$EndNodes")) +
                                ": expected node 9 of 9 (count on line 9), found $EndNodes");

  const std::string too_few = replaced(msh22(), "$Nodes\n8\n", "$Nodes\n7\n");
  file = dir.write("few.msh", too_few);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(too_few, "51 ")) +
                                ": expected $EndNodes after 7 nodes (count on line 9), found '51'");
}

TEST(MshReader, WrongElementCountIn41IsReported) {
  TempDir dir;
  const std::string text = replaced(msh41(), "$Elements\n2 7 1 7\n", "$Elements\n2 8 1 7\n");
  const auto file = dir.write("count.msh", text);
  EXPECT_EQ(error_of(file),
            file.string() + ":" + std::to_string(line_of(text, std::string("7") + tet_nodes(5))) +
                ": the $Elements header on line " + std::to_string(line_of(text, "2 8 1 7")) +
                " says 8 elements, its blocks hold 7");
}

TEST(MshReader, UnknownNodeTagNamesElementAndLine) {
  TempDir dir;
  const std::string bad = "12 4 2 1 1 9000" + tet_nodes(2).substr(tet_nodes(2).find(' ', 1));
  const std::string text = replaced(msh22(), "12 4 2 1 1" + tet_nodes(2), bad);
  const auto file = dir.write("bar.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "12 4 2")) +
                                ": element 12: node 9000 not found in $Nodes (mesh has 8 nodes)");
}

TEST(MshReader, MalformedElementLineIsReported) {
  TempDir dir;
  std::string text = replaced(msh41(), std::string("4") + tet_nodes(2) + "\n",
                              std::string("4") + tet_nodes(2) + " 65\n");
  auto file = dir.write("long.msh", text);
  EXPECT_EQ(error_of(file),
            file.string() + ":" + std::to_string(line_of(text, std::string("4") + tet_nodes(2))) +
                ": element 4: expected 5 values (element tag, 4 node tags), found 6");
  text = replaced(msh22(), "2 1 2 0 1", "2 1 9 0 1");
  file = dir.write("tags.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "2 1 9")) +
                                ": element 2: tag count 9 does not fit the line's 7 values");
}

TEST(MshReader, InvertedElementNamesElementAndLine) {
  TempDir dir;
  std::array<int, 4> nodes = cube.tets()[3].nodes;
  std::swap(nodes[0], nodes[1]);
  const std::string swapped = node_tags(nodes);
  const std::string text = replaced(msh22(), "13 4 2 1 1" + tet_nodes(3), "13 4 2 1 1" + swapped);
  const auto file = dir.write("inv.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "13 4 2")) +
                                ": element 13: inverted tetrahedron (volume -0.166667)");
}

TEST(MshReader, NonFiniteAndNonNumericCoordinatesAreReported) {
  TempDir dir;
  const std::string line = node_line(5);  // "65 1.000000 0.000000 1.000000"
  for (const std::string bad : {"nan", "1e999", "-inf"}) {
    const std::string text = replaced(msh22(), line, "65 " + bad + " 0 1\n");
    const auto file = dir.write("nan.msh", text);
    EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "65 " + bad)) +
                                  ": node 65: x is not a finite number: '" + bad + "'");
  }
  const std::string text = replaced(msh22(), line, "65 0.5 zero 1\n");
  const auto file = dir.write("word.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "65 0.5")) +
                                ": node 65: expected a number for y, got 'zero'");
}

TEST(MshReader, DuplicateNodeTagIsReported) {
  TempDir dir;
  const std::string text = replaced(msh22(), node_line(4), "100 0 0 1\n");
  const auto file = dir.write("dup.msh", text);
  EXPECT_EQ(error_of(file), file.string() + ":" + std::to_string(line_of(text, "100 0 0 1")) +
                                ": node 100: tag appears twice in $Nodes");
}

TEST(MshReader, BinaryAndUnsupportedVersionsAreRefused) {
  TempDir dir;
  auto file = dir.write("bin.msh", replaced(msh41(), "4.1 0 8", "4.1 1 8"));
  EXPECT_EQ(error_of(file), file.string() + ":2: binary MSH not supported, save as ASCII");
  file = dir.write("v40.msh", replaced(msh41(), "4.1 0 8", "4 0 8"));
  EXPECT_EQ(error_of(file),
            file.string() + ":2: unsupported MSH version 4 (supported: 2.2 and 4.1 ASCII)");
  file = dir.write("obj.msh", "v 0 0 0\n");
  EXPECT_EQ(error_of(file),
            file.string() + ":1: expected $MeshFormat (a Gmsh MSH file), found 'v'");
  file = dir.write("empty.msh", "\n\n");
  EXPECT_EQ(error_of(file), file.string() + ": empty file, expected a Gmsh MSH file");
}

TEST(MshReader, SurfaceOnlyMeshHasNoTetrahedra) {
  TempDir dir;
  std::string text = msh22();
  text =
      text.substr(0, text.find("$Elements")) + "$Elements\n1\n1 2 2 0 1 100 93 86\n$EndElements\n";
  const auto file = dir.write("surface.msh", text);
  EXPECT_EQ(error_of(file), file.string() +
                                ": no linear tetrahedra (element type 4); mesh the volume in 3D "
                                "and save again");
}

TEST(MshReader, MissingSectionsAreReported) {
  TempDir dir;
  const std::string text = msh22();
  auto file = dir.write("nodes.msh", text.substr(0, text.find("$Elements")));
  EXPECT_EQ(error_of(file), file.string() + ": no $Elements section");
  file = dir.write("unended.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nhello\n");
  EXPECT_EQ(error_of(file), file.string() +
                                ":5: file ends early: the section started on line 4 has no "
                                "$EndComments");
}

// Garbage of every kind must end in InputError: never a crash, a hang or another exception.
TEST(MshReader, GarbageOnlyEverRaisesInputError) {
  TempDir dir;
  std::mt19937 rng(42);
  const std::string valid[] = {msh22(), msh41()};
  for (int trial = 0; trial < 400; ++trial) {
    std::string text = valid[trial % 2];
    switch (trial % 4) {
      case 0:  // random bytes
        text.assign(std::uniform_int_distribution<int>(0, 300)(rng), '\0');
        for (char& c : text) c = static_cast<char>(rng());
        break;
      case 1:  // truncated
        text.resize(std::uniform_int_distribution<std::size_t>(0, text.size())(rng));
        break;
      default:  // a few bytes replaced by digits, signs, separators or anything
        for (int k = 0; k < 3; ++k) {
          const char pool[] = "0123456789-+.e $\n\t\x01\xff";
          text[std::uniform_int_distribution<std::size_t>(0, text.size() - 1)(rng)] =
              pool[std::uniform_int_distribution<int>(0, sizeof(pool) - 2)(rng)];
        }
    }
    const auto file = dir.write("fuzz.msh", text);
    try {
      read_msh(file);
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << "trial " << trial << ": " << e.what();
    }
  }
}

}  // namespace
}  // namespace shapectl
