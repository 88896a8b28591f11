#pragma once
// 16-bit grayscale PNG depth images (RealSense, Azure Kinect: value × scale = depth), read and
// written with libpng.
#include <cstdint>
#include <filesystem>
#include <string>

#include <shapectl/calib/depth_image.hpp>

namespace shapectl {

// The largest PNG file read (a 4 Mpx 16-bit image barely compresses below 8 MB).
inline constexpr std::uintmax_t max_depth_png_bytes = 64u << 20;

// The pixels of `bytes` (the whole file; `name` names it in messages). Throws InputError
// naming the file and what was expected: not a PNG, not 16-bit grayscale ("expected a 16-bit
// grayscale PNG, got 8-bit RGB"), more than max_depth_image_pixels (checked from the header,
// before anything is allocated), a corrupt or truncated file (libpng's message).
DepthPixels read_depth_png(const std::string& name, const std::string& bytes);
// The pixels as a 16-bit grayscale PNG file's bytes.
std::string depth_png_bytes(const DepthPixels& pixels);

}  // namespace shapectl
