#pragma once
// An N x 3 NumPy array (a .npy file) as points.
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// `bytes` is the whole file, `name` names it in messages. Format 1.0 or 2.0, descr '<f8' or
// '<f4', fortran_order False, shape (N, 3) with N <= max_point_cloud_points, exactly N x 3
// values after the header. Throws InputError "name: header 'shape': expected (N, 3), got (4,)",
// "name: point 7: ...": a bad magic string, version, header or dtype, a truncated file, a
// non-finite coordinate.
std::vector<Vec3> read_npy_points(const std::string& name, const std::string& bytes);

}  // namespace shapectl
