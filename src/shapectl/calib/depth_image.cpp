#include <shapectl/calib/depth_image.hpp>

#include <cmath>

namespace shapectl {

DepthImage depth_from_pixels(const DepthPixels& pixels, double scale) {
  DepthImage image{pixels.width, pixels.height, std::vector<double>(pixels.values.size())};
  for (std::size_t i = 0; i < pixels.values.size(); ++i)
    image.depth[i] = pixels.values[i] ? pixels.values[i] * scale : NAN;
  return image;
}

DepthPixels pixels_from_depth(const DepthImage& image, double scale) {
  DepthPixels pixels{image.width, image.height, std::vector<std::uint16_t>(image.depth.size())};
  for (std::size_t i = 0; i < image.depth.size(); ++i) {
    const double value = std::round(image.depth[i] / scale);
    pixels.values[i] = value >= 1 && value <= 65535 ? static_cast<std::uint16_t>(value) : 0;
  }
  return pixels;
}

std::vector<Vec3> back_project(const DepthImage& image, const PinholeIntrinsics& intrinsics,
                               const Eigen::Isometry3d& T_world_camera, int stride) {
  std::vector<Vec3> points;
  for (int v = 0; v < image.height; v += stride)
    for (int u = 0; u < image.width; u += stride) {
      const double z = image.depth[static_cast<std::size_t>(v) * image.width + u];
      if (!(z > 0 && std::isfinite(z))) continue;
      const Vec3 camera(z * (u - intrinsics.cx) / intrinsics.fx,
                        z * (v - intrinsics.cy) / intrinsics.fy, z);
      points.push_back(T_world_camera * camera);
    }
  return points;
}

}  // namespace shapectl
