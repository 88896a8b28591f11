#pragma once
// Point clouds from a file, chosen by extension (case ignored), coordinates in metres:
//   .xyz  text, one point a line: x y z, then any further columns (ignored); '#' starts a comment
//   .ply  ascii or binary_little_endian 1.0; the "vertex" element's float or double x, y, z
//         (other properties skipped by their types, list properties too); elements before the
//         vertices are skipped, those after them ignored
//   .npy  NumPy format 1.0 or 2.0, dtype '<f8' or '<f4', shape (N, 3), C order
#include <cstdint>
#include <filesystem>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// The most points a file may hold (48 MB as Vec3) and the largest file read (a .xyz with a
// colour and a normal per point is ~100 bytes a line).
inline constexpr std::size_t max_point_cloud_points = 2'000'000;
inline constexpr std::uintmax_t max_point_cloud_file_bytes = 256u << 20;

// The points in file order (possibly none). Every problem is an InputError naming the file and
// the line, header field or point and what was expected: a missing, oversize or non-regular
// file, an unknown extension, a malformed or truncated file, a non-finite coordinate, more than
// max_point_cloud_points points.
std::vector<Vec3> read_point_cloud(const std::filesystem::path& file);

}  // namespace shapectl
