#pragma once
// The vertices of a PLY file (ascii or binary_little_endian 1.0) as points.
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// `bytes` is the whole file, `name` names it in messages. Ascii data holds one element instance
// a line (as every writer puts it). The "vertex" element needs float or double properties x, y,
// z; its other properties (lists too) are skipped by their types, the elements before it
// skipped, those after it ignored. At most max_point_cloud_points vertices. Throws InputError
// "name:line: ..." for the header and ascii data, "name: vertex i: ..." for binary data: a
// malformed header, an unsupported format, a truncated file, a non-finite x, y or z.
std::vector<Vec3> read_ply_points(const std::string& name, std::string bytes);

}  // namespace shapectl
