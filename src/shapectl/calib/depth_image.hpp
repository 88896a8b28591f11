#pragma once
// A depth image and the pinhole camera that took it (docs/calibration.md, "Depth images").
// Camera frame: OpenCV's, x right, y down, z forward along the optical axis. Pixel (u, v)
// (column u, row v from the top left) looks along the ray through image coordinates (u, v),
// integer coordinates being pixel centres (OpenCV's convention): a depth z there is the point
//   p_camera = (z (u − cx) / fx,  z (v − cy) / fy,  z).
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include <shapectl/types.hpp>

namespace shapectl {

// The largest image read or made: 4 Mpx (2048 × 2048; depth cameras give ~1 Mpx), 32 MB as
// doubles.
inline constexpr std::size_t max_depth_image_pixels = 4u << 20;

struct PinholeIntrinsics {
  double fx = 0, fy = 0;  // focal lengths, pixels (> 0)
  double cx = 0, cy = 0;  // principal point, pixels
};

// Depth along the optical axis, m, row-major (depth[v * width + u]); NaN: no reading.
struct DepthImage {
  int width = 0, height = 0;
  std::vector<double> depth;
};

// Raw 16-bit values (a PNG's), row-major; 0: no reading.
struct DepthPixels {
  int width = 0, height = 0;
  std::vector<std::uint16_t> values;
};

// The pixels' depths: value × scale (m), 0 → NaN.
DepthImage depth_from_pixels(const DepthPixels& pixels, double scale);
// The image quantized to value = round(depth / scale); NaN, and depths beyond 65535 × scale
// or not positive, → 0 (no reading).
DepthPixels pixels_from_depth(const DepthImage& image, double scale);

// Every `stride`-th pixel of every `stride`-th row (from (0, 0)) with a finite positive depth,
// back-projected and placed in the world by T_world_camera, in row-major order.
std::vector<Vec3> back_project(const DepthImage& image, const PinholeIntrinsics& intrinsics,
                               const Eigen::Isometry3d& T_world_camera, int stride = 1);

}  // namespace shapectl
