#pragma once
// Depth images as 2-D NumPy arrays (.npy): float32 or float64, shape (height, width), C order;
// value × scale = depth (m); NaN or 0 (or any value not positive): no reading.
#include <cstdint>
#include <string>

#include <shapectl/calib/depth_image.hpp>

namespace shapectl {

// The largest .npy depth image read: 4 Mpx of float64 and its header.
inline constexpr std::uintmax_t max_depth_npy_bytes = 8 * max_depth_image_pixels + 4096;

// `bytes` is the whole file, `name` names it in messages. Throws InputError "name: header
// 'shape': expected (height, width), got (4, 3, 2)": a bad header (calib/npy_header.hpp), dtype
// not '<f4' or '<f8', a shape not 2-D or of more than max_depth_image_pixels, data of the wrong
// size, an infinite value.
DepthImage read_depth_npy(const std::string& name, const std::string& bytes, double scale);
// The image (m) as a float32 .npy file's bytes; no reading as NaN.
std::string depth_npy_bytes(const DepthImage& image);

}  // namespace shapectl
