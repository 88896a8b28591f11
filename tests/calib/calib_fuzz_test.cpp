// Mutated point cloud files (.xyz, ascii and binary .ply, .npy) and observation JSON: each
// reads or throws InputError; what reads is finite and within the limits.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>

#include <shapectl/calib/npy_points.hpp>
#include <shapectl/calib/observations.hpp>
#include <shapectl/calib/ply_points.hpp>
#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/calib/xyz_points.hpp>

#include "io/text_mutator.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const std::vector<Vec3>& seed_points() {
  static const std::vector<Vec3> points = [] {
    std::vector<Vec3> p;
    for (int i = 0; i < 12; ++i) p.emplace_back(0.01 * i, -0.02 * i, 0.5 + 0.001 * i * i);
    return p;
  }();
  return points;
}

std::string xyz() {
  std::ostringstream s;
  s.precision(17);
  s << "# x y z intensity\n";
  for (const Vec3& p : seed_points()) s << p.transpose() << " 7\n";
  return s.str();
}

std::string ascii_ply() {
  std::ostringstream s;
  s << "ply\nformat ascii 1.0\nelement vertex " << seed_points().size()
    << "\nproperty double x\nproperty uchar red\nproperty double y\nproperty list uchar int l\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& p : seed_points()) s << p.x() << " 1 " << p.y() << " 2 5 6 " << p.z() << "\n";
  return s.str() + "3 0 1 2\n";
}

template <class T>
void put(std::string& s, T value) {
  s.append(reinterpret_cast<const char*>(&value), sizeof value);  // little-endian hosts
}

std::string binary_ply() {
  std::ostringstream header;
  header
      << "ply\nformat binary_little_endian 1.0\nelement vertex " << seed_points().size()
      << "\nproperty float x\nproperty short s\nproperty double y\nproperty list uchar ushort l\n"
         "property double z\nend_header\n";
  std::string s = header.str();
  for (const Vec3& p : seed_points()) {
    put(s, static_cast<float>(p.x()));
    put<std::int16_t>(s, -3);
    put(s, p.y());
    put<std::uint8_t>(s, 2);
    put<std::uint16_t>(s, 1);
    put<std::uint16_t>(s, 2);
    put(s, p.z());
  }
  return s;
}

std::string npy() {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" +
                       std::to_string(seed_points().size()) + ", 3), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string s = "\x93NUMPY";
  s += '\1';
  s += '\0';
  put<std::uint16_t>(s, static_cast<std::uint16_t>(header.size()));
  s += header;
  for (const Vec3& p : seed_points())
    for (int k = 0; k < 3; ++k) put(s, p[k]);
  return s;
}

const test::TextMutator kCloudMutator({"nan",
                                       "inf",
                                       "-1e999",
                                       "1e-400",
                                       "-1",
                                       "0",
                                       "4294967295",
                                       "99999999999999999999",
                                       "x",
                                       "\n",
                                       " ",
                                       "#",
                                       "ply\n",
                                       "end_header\n",
                                       "element vertex 3000000\n",
                                       "property list uchar double q\n",
                                       "format ascii 1.0\n",
                                       "binary_big_endian",
                                       "'shape': (5,)",
                                       "True",
                                       "'<f4'",
                                       "(",
                                       ")",
                                       "'",
                                       "\0",
                                       "\xff\xff\xff\xff"});

void expect_valid(const std::vector<Vec3>& points) {
  ASSERT_LE(points.size(), max_point_cloud_points);
  for (const Vec3& p : points) ASSERT_TRUE(p.allFinite());
}

TEST(CalibFuzz, ValidSeedsRead) {
  const test::TempDir dir;
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"a.xyz", xyz()},
                                   {"b.ply", ascii_ply()},
                                   {"c.ply", binary_ply()},
                                   {"d.npy", npy()}}) {
    const std::vector<Vec3> points = read_point_cloud(dir.write(name, text));
    ASSERT_EQ(points.size(), seed_points().size()) << name;
    for (std::size_t i = 0; i < points.size(); ++i)
      EXPECT_LT((points[i] - seed_points()[i]).norm(), 1e-7) << name << " point " << i;  // float x
  }
}

// In memory: the readers read_point_cloud dispatches to, on the bytes it would read.
TEST(CalibFuzz, MutatedPointCloudFilesReadOrAreInputErrors) {
  using Reader = std::function<std::vector<Vec3>(const std::string&)>;
  const Reader xyz_reader = [](const std::string& text) { return read_xyz_points("m.xyz", text); };
  const Reader ply_reader = [](const std::string& text) { return read_ply_points("m.ply", text); };
  const Reader npy_reader = [](const std::string& text) { return read_npy_points("m.npy", text); };
  for (const auto& [name, seed, reader] :
       {std::tuple<std::string, std::string, Reader>{"xyz", xyz(), xyz_reader},
        {"ascii ply", ascii_ply(), ply_reader},
        {"binary ply", binary_ply(), ply_reader},
        {"npy", npy(), npy_reader}}) {
    const test::FuzzCounts counts =
        test::fuzz_parser({seed}, kCloudMutator, 1000, 5,
                          [&](const std::string& text) { expect_valid(reader(text)); });
    EXPECT_GT(counts.refused, 100) << name;
    EXPECT_GT(counts.parsed, 10) << name;
  }
}

TEST(CalibFuzz, MutatedObservationJsonReadsOrIsAnInputError) {
  const std::string seed = R"({"frames": [
      {"markers": [{"node": 3, "position": [0.1, 0.2, 0.3]}, {"node": 0, "position": [0, 0, 1]}],
       "sigma": 0.002, "time": 1.5},
      {"points": [[0.1, 0, 0], [0, 0.25, 1e-3]], "markers": []}]})";
  const test::TextMutator mutator({"nan", "1e999", "-1", "0", "5", "99999999999", "\"x\"", "null",
                                   "[]", "{}", "[[0,0,0]]", "\"points_file\": \"a.xyz\",",
                                   "\"joints\": {},", "{\"node\": 1, \"position\": [0,0,0]}", ","});
  const test::FuzzCounts counts =
      test::fuzz_parser({seed}, mutator, 1500, 9, [](const std::string& text) {
        const Observations obs =
            read_observations(JsonInput(parse_json_text(text, "obs.json"), "obs.json"),
                              {.node_count = 5});
        for (const ObservationFrame& f : obs.frames) {
          ASSERT_TRUE(!f.markers.empty() || !f.points.empty());
          ASSERT_GT(f.sigma, 0);
          for (const ObservedMarker& m : f.markers) ASSERT_TRUE(m.node >= 0 && m.node < 5);
          expect_valid(f.points);
        }
      });
  EXPECT_GT(counts.refused, 300);
  EXPECT_GT(counts.parsed, 100);
}

}  // namespace
}  // namespace shapectl
