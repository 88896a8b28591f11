#include <shapectl/calib/point_cloud_file.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::input_error_of;
using test::TempDir;

// The little-endian bytes of a number, as binary PLY and NumPy store them.
bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

template <class T>
std::string bytes_of(T value) {
  std::string s(sizeof(T), '\0');
  std::memcpy(s.data(), &value, sizeof(T));
  return s;
}

// The error reading `bytes` as file `name` gives, after the file's name (which it must start with).
std::string error_after_name(const TempDir& dir, const std::string& name,
                             const std::string& bytes) {
  const std::string file = dir.write(name, bytes).string();
  const std::string message = input_error_of([&] { read_point_cloud(file); });
  EXPECT_EQ(message.rfind(file, 0), 0u) << message;
  return message.substr(std::min(file.size(), message.size()));
}

// A .npy file: magic, version, header length, the dict padded with spaces to a multiple of 64
// bytes (ending in '\n'), then `data`.
std::string npy_file(const std::string& dict, const std::string& data, int major = 1) {
  const std::size_t prefix = major == 1 ? 10 : 12;
  std::string header = dict;
  while ((prefix + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out = "\x93NUMPY" + std::string(1, char(major)) + std::string(1, '\0');
  out += major == 1 ? bytes_of<std::uint16_t>(static_cast<std::uint16_t>(header.size()))
                    : bytes_of<std::uint32_t>(static_cast<std::uint32_t>(header.size()));
  return out + header + data;
}

std::string f8_rows(std::initializer_list<double> values) {
  std::string s;
  for (const double v : values) s += bytes_of(v);
  return s;
}

TEST(PointCloudFile, XyzReadsThreeColumnsSkippingCommentsAndExtraColumns) {
  TempDir dir;
  const auto file =
      dir.write("cloud.xyz",
                "# scanner output\n0 0 0\n1 2 3 255 0 0  # red\n\n  -1.5e-3\t+2 3.25\r\n");
  const std::vector<Vec3> points = read_point_cloud(file);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0], Vec3(0, 0, 0));
  EXPECT_EQ(points[1], Vec3(1, 2, 3));
  EXPECT_EQ(points[2], Vec3(-1.5e-3, 2, 3.25));
}

TEST(PointCloudFile, XyzErrorsNameTheLine) {
  TempDir dir;
  const auto two = dir.write("two.xyz", "0 0 0\n1 2\n");
  EXPECT_EQ(input_error_of([&] { read_point_cloud(two); }),
            two.string() + ":2: expected at least 3 values (x y z), found 2");
  const auto word = dir.write("word.xyz", "# c\n0 abc 0\n");
  EXPECT_EQ(input_error_of([&] { read_point_cloud(word); }),
            word.string() + ":2: point 0: expected a number for y, got 'abc'");
  const auto nan = dir.write("nan.xyz", "0 0 0\n1 1 1\nnan 0 0\n");
  EXPECT_EQ(input_error_of([&] { read_point_cloud(nan); }),
            nan.string() + ":3: point 2: x is not a finite number: 'nan'");
}

TEST(PointCloudFile, UnknownExtensionAndMissingFileNameTheFile) {
  TempDir dir;
  const auto pcd = dir.write("cloud.pcd", "0 0 0\n");
  EXPECT_EQ(input_error_of([&] { read_point_cloud(pcd); }),
            pcd.string() + ": unknown point cloud format '.pcd' (supported: .xyz, .ply, .npy)");
  const auto missing = dir.path() / "missing.PLY";
  EXPECT_PRED2(contains, input_error_of([&] { read_point_cloud(missing); }),
               missing.string() + ": cannot open file");
}

const char* const ascii_ply =
    "ply\n"
    "format ascii 1.0\n"
    "comment made by hand\n"
    "element vertex 3\n"
    "property float x\n"
    "property uchar red\n"
    "property double y\n"
    "property list uchar int ring\n"
    "property float z\n"
    "element face 1\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 7 0 0 0\n"
    "1.5 255 -2 2 8 9 3\n"
    "0.25 0 0.5 1 4 -1e-3\n"
    "3 0 1 2\n";

TEST(PointCloudFile, AsciiPlyReadsXyzSkippingOtherPropertiesAndElements) {
  TempDir dir;
  const std::vector<Vec3> points = read_point_cloud(dir.write("mesh.ply", ascii_ply));
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0], Vec3(0, 0, 0));
  EXPECT_EQ(points[1], Vec3(1.5, -2, 3));
  EXPECT_EQ(points[2], Vec3(0.25, 0.5, -1e-3));
}

// ascii_ply with `from` replaced by `to`.
std::string ascii_ply_with(const std::string& from, const std::string& to) {
  std::string s = ascii_ply;
  return s.replace(s.find(from), from.size(), to);
}

TEST(PointCloudFile, AsciiPlyErrorsNameTheLine) {
  TempDir dir;
  EXPECT_EQ(error_after_name(dir, "short.ply",
                             ascii_ply_with("1.5 255 -2 2 8 9 3", "1.5 255 -2 2 8 9")),
            ":14: vertex 1: expected a value for property 'z', the line has 6 values");
  EXPECT_EQ(error_after_name(dir, "list.ply", ascii_ply_with("0.25 0 0.5 1 4", "0.25 0 0.5 9 4")),
            ":15: vertex 2: list 'ring': length 9 does not fit the line's 6 values");
  EXPECT_EQ(error_after_name(dir, "early.ply",
                             ascii_ply_with("1.5 255 -2 2 8 9 3\n0.25 0 0.5 1 4 -1e-3\n3 0 1 2\n",
                                            "")),
            ":13: file ends early: expected vertex 1");
}

TEST(PointCloudFile, PlyHeaderErrorsSayWhatWasExpected) {
  TempDir dir;
  auto error_of = [&](const std::string& bytes) { return error_after_name(dir, "h.ply", bytes); };
  EXPECT_EQ(error_of("PLY\nformat ascii 1.0\nend_header\n"),
            ":1: expected 'ply' (the PLY magic line)");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
            ": header: no 'end_header' line in the first 65536 bytes");
  EXPECT_EQ(error_of("ply\nformat binary_big_endian 1.0\nend_header\n"),
            ":2: format: expected ascii or binary_little_endian, got 'binary_big_endian'");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                     "end_header\n0 0\n"),
            ":3: element 'vertex': expected one property z, found 0");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\n"
                     "property float z\nend_header\n0 0 0\n"),
            ":3: element 'vertex': expected property x of type float or double");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty half y\n"
                     "end_header\n"),
            ":5: property: expected a PLY type (char, uchar, short, ushort, int, uint, float, "
            "double or int8 ... float64), got 'half'");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement face 1\nproperty uchar a\nend_header\n1\n"),
            ": header: no 'vertex' element");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 3000000\nproperty float x\n"
                     "property float y\nproperty float z\nend_header\n"),
            ":3: element 'vertex': 3000000 vertices, more than the limit of 2000000");
  EXPECT_EQ(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                     "property float z\nend_header junk\nend_header\n0 0 0\n"),
            ":7: end_header: expected 1 values (end_header alone), found 2");
}

// Binary: x float, a uchar, y double, a list of shorts, z float; then a face element.
std::string binary_vertex(float x, double y, float z, int list_length) {
  std::string s = bytes_of(x) + bytes_of<std::uint8_t>(200) + bytes_of(y) +
                  bytes_of<std::uint8_t>(static_cast<std::uint8_t>(list_length));
  for (int k = 0; k < list_length; ++k) s += bytes_of<std::int16_t>(static_cast<std::int16_t>(-k));
  return s + bytes_of(z);
}

const std::string binary_header =
    "ply\r\n"
    "format binary_little_endian 1.0\r\n"
    "element vertex 2\r\n"
    "property float x\r\n"
    "property uchar intensity\r\n"
    "property double y\r\n"
    "property list uint8 int16 ring\r\n"
    "property float z\r\n"
    "element face 5\r\n"
    "property list uchar int vertex_indices\r\n"
    "end_header\r\n";

TEST(PointCloudFile, BinaryPlyReadsXyzSkippingListsByTheirTypes) {
  TempDir dir;
  const auto file =
      dir.write("b.ply", binary_header + binary_vertex(0.5f, -1.25, 2.0f, 3) +
                             binary_vertex(-4.0f, 1e-3, 0.125f, 0) + "trailing faces");
  const std::vector<Vec3> points = read_point_cloud(file);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], Vec3(0.5, -1.25, 2.0));
  EXPECT_EQ(points[1], Vec3(-4.0, 1e-3, 0.125));
}

TEST(PointCloudFile, BinaryPlySkipsElementsBeforeTheVertices) {
  TempDir dir;
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement camera 2\nproperty list uchar double pose\n"
      "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  const std::string cameras =
      bytes_of<std::uint8_t>(2) + f8_rows({9, 9}) + bytes_of<std::uint8_t>(0);
  const auto file = dir.write("c.ply", header + cameras + f8_rows({1, 2, 3}));
  EXPECT_EQ(read_point_cloud(file), std::vector<Vec3>{Vec3(1, 2, 3)});
}

TEST(PointCloudFile, BinaryPlyTruncationHugeCountsAndNanAreErrors) {
  TempDir dir;
  const std::string full =
      binary_header + binary_vertex(0.5f, -1.25, 2.0f, 3) + binary_vertex(-4.0f, 1e-3, 0.125f, 0);
  const auto cut = dir.write("cut.ply", full.substr(0, full.size() - 1));
  EXPECT_EQ(input_error_of([&] { read_point_cloud(cut); }),
            cut.string() + ": vertex 1: the file ends inside it (truncated)");
  // A list announcing more items than the file holds.
  const auto list =
      dir.write("list.ply", binary_header + binary_vertex(0.5f, -1.25, 2.0f, 3).substr(0, 13) +
                                bytes_of<std::uint8_t>(250) + "xx");
  EXPECT_EQ(input_error_of([&] { read_point_cloud(list); }),
            list.string() + ": vertex 0: the file ends inside it (truncated)");
  // A huge element before the vertices ends at the end of the file, not after 4e9 steps.
  const auto huge = dir.write("huge.ply",
                              "ply\nformat binary_little_endian 1.0\nelement junk 4000000000\n"
                              "property uchar a\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float z\nend_header\n" +
                                  std::string(1000, 'j'));
  EXPECT_EQ(input_error_of([&] { read_point_cloud(huge); }),
            huge.string() + ": junk 1000: the file ends inside it (truncated)");
  const auto nan =
      dir.write("nan.ply", binary_header + binary_vertex(0.5f, -1.25, 2.0f, 0) +
                               binary_vertex(std::numeric_limits<float>::quiet_NaN(), 0, 0, 0));
  EXPECT_EQ(input_error_of([&] { read_point_cloud(nan); }),
            nan.string() + ": vertex 1: expected finite x, y, z");
}

TEST(PointCloudFile, NpyReadsFloat64AndFloat32InFormats1And2) {
  TempDir dir;
  const auto f8 =
      dir.write("f8.npy", npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                                   f8_rows({1, 2, 3, -0.5, 1e-3, 7})));
  EXPECT_EQ(read_point_cloud(f8), (std::vector<Vec3>{Vec3(1, 2, 3), Vec3(-0.5, 1e-3, 7)}));
  std::string f4_data;
  for (const float v : {0.25f, -8.0f, 1.5f}) f4_data += bytes_of(v);
  const auto f4 =
      dir.write("f4.npy",
                npy_file("{\"shape\": (1,3), \"fortran_order\": False, \"descr\": \"<f4\"}",
                         f4_data, 2));
  EXPECT_EQ(read_point_cloud(f4), std::vector<Vec3>{Vec3(0.25, -8, 1.5)});
  const auto empty =
      dir.write("empty.npy",
                npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 3), }", ""));
  EXPECT_TRUE(read_point_cloud(empty).empty());
}

TEST(PointCloudFile, NpyErrorsNameTheHeaderFieldOrData) {
  TempDir dir;
  auto error_of = [&](const std::string& bytes) { return error_after_name(dir, "a.npy", bytes); };
  const std::string six = f8_rows({1, 2, 3, 4, 5, 6});
  EXPECT_EQ(error_of("PK\x03\x04 a zip file"),
            ": expected the NumPy magic string \\x93NUMPY (not a .npy file)");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }", six)),
            ": header 'fortran_order': expected False (C order), got True");
  EXPECT_EQ(
      error_of(npy_file("{'descr': '>f8', 'fortran_order': False, 'shape': (2, 3), }", six)),
      ": header 'descr': expected '<f8' or '<f4' (little-endian float64 or float32), got '>f8'");
  EXPECT_EQ(
      error_of(npy_file("{'descr': '<i8', 'fortran_order': False, 'shape': (2, 3), }", six)),
      ": header 'descr': expected '<f8' or '<f4' (little-endian float64 or float32), got '<i8'");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (6,), }", six)),
            ": header 'shape': expected (N, 3), got (6,)");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }", six)),
            ": header 'shape': expected (N, 3), got (3, 2)");
  EXPECT_EQ(error_of(
                npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000, 3), }",
                         six)),
            ": header 'shape': 1000000000000 points, more than the limit of 2000000");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 3), }", six)),
            ": data: expected 3 x 3 values of 8 bytes (72 bytes) after the header, found 48 bytes");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': False}", six)),
            ": header: expected the keys 'descr', 'fortran_order' and 'shape'");
  EXPECT_PRED2(
      contains,
      error_of(
          npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), 'extra': 1}", six)),
      ": header: expected the key 'descr', 'fortran_order' or 'shape', each once at character");
  EXPECT_PRED2(contains,
               error_of(npy_file("{'descr': '<f8', 'fortran_order': Maybe, 'shape': (2, 3)}", six)),
               ": header: expected True or False at character 34");
  EXPECT_EQ(error_of(npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                              f8_rows({1, 2, 3, 4, std::numeric_limits<double>::infinity(), 6}))),
            ": point 1: expected finite coordinates");
  std::string v3 = npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", six, 2);
  v3[6] = 3;
  EXPECT_EQ(error_of(v3), ": version: expected format 1.0 or 2.0, got 3.0");
  std::string long_header =
      npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", six);
  long_header.replace(8, 2, bytes_of<std::uint16_t>(60000));
  EXPECT_EQ(error_of(long_header), ": header: the file ends inside it (60000 bytes announced)");
}

}  // namespace
}  // namespace shapectl
