#include <shapectl/io/vtu_writer.hpp>

#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::read_text;
using test::TempDir;

// Two tets sharing the face (1, 2, 3).
Positions two_tet_positions() {
  Positions x(15);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  return x;
}
const std::vector<std::array<int, 4>> two_tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};

TEST(VtuWriter, WritesPointsCellsAndFields) {
  TempDir dir;
  const auto file = dir.path() / "mesh.vtu";
  Positions u = Positions::Zero(15);
  u[14] = 0.25;
  write_vtu(file, two_tet_positions(), two_tets, {{"displacement", u}});
  const std::string text = read_text(file);
  EXPECT_NE(text.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPoints=\"5\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"displacement\" NumberOfComponents=\"3\""), std::string::npos);
  EXPECT_NE(text.find("0 0 0.25\n</DataArray>"), std::string::npos);
  EXPECT_NE(text.find("0 1 2 3\n1 2 3 4\n"), std::string::npos);
  EXPECT_NE(text.find("Name=\"offsets\" format=\"ascii\">\n4\n8\n"), std::string::npos);
  EXPECT_NE(text.find("format=\"ascii\">\n10\n10\n</DataArray>"), std::string::npos);
  EXPECT_NE(text.find("</VTKFile>"), std::string::npos);
  // Only the target remains: the temporary file was renamed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(VtuWriter, MissingDirectoryIsNamedAndNothingIsWritten) {
  TempDir dir;
  const auto file = dir.path() / "absent" / "mesh.vtu";
  try {
    write_vtu(file, two_tet_positions(), two_tets);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": cannot write: directory '" +
                                         file.parent_path().string() + "' does not exist");
  }
}

TEST(VtuWriter, FailedWriteLeavesWhatWasThereAndNoTemporaryFile) {
  TempDir dir;
  // The last step, renaming over the target, fails when the target is a directory.
  const auto target = dir.path() / "mesh.vtu";
  dir.write("mesh.vtu/previous.txt", "previous result");
  EXPECT_THROW(write_vtu(target, two_tet_positions(), two_tets), InputError);
  EXPECT_EQ(read_text(target / "previous.txt"), "previous result");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(VtuWriter, BadArgumentsTouchNothing) {
  TempDir dir;
  const auto file = dir.write("mesh.vtu", "previous result");
  EXPECT_THROW(write_vtu(file, two_tet_positions(), {{0, 1, 2, 5}}), std::invalid_argument);
  EXPECT_THROW(write_vtu(file, two_tet_positions(), two_tets, {{"u", Positions::Zero(3)}}),
               std::invalid_argument);
  EXPECT_EQ(read_text(file), "previous result");
}

}  // namespace
}  // namespace shapectl
