#pragma once
// The header of a NumPy .npy file (format 1.0 or 2.0): what an array's readers share
// (calib/npy_points.hpp, calib/depth_npy.hpp), and the header an array is written with.
#include <cstdint>
#include <string>
#include <vector>

namespace shapectl {

struct NpyArray {
  std::string descr;  // '<f8', '<f4', ...
  std::vector<std::uint64_t> shape;
  std::size_t data_start = 0;  // byte offset of the values in the file
};

// The header of `bytes` (the whole file; `name` names it in messages): the magic string, the
// version, the dict's syntax and C order checked; the dtype, the shape and the data's size are
// the caller's to check. Throws InputError "name: header: expected ...".
NpyArray read_npy_header(const std::string& name, const std::string& bytes);
// "(4, 3)", "(4,)": a shape as NumPy writes it.
std::string npy_shape_text(const std::vector<std::uint64_t>& shape);
// A format 1.0 header for a C-order array of `descr` and `shape`, padded to 64 bytes.
std::string npy_header_bytes(const std::string& descr, const std::vector<std::uint64_t>& shape);

}  // namespace shapectl
