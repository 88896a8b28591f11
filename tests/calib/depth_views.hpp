#pragma once
// Depth cameras for tests: a camera placed by where it looks, what it sees of an object
// (SimulatedCamera::depth_image) and its frame's "depth_image".
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/io/json_eigen.hpp>

namespace shapectl::test {

// T_world_camera of a camera at `eye` looking at `target`, OpenCV axes: z forward, x right,
// y down, "down" being −up as far as it is square to the view.
inline Eigen::Isometry3d look_at(const Vec3& eye, const Vec3& target,
                                 const Vec3& up = Vec3::UnitZ()) {
  const Vec3 z = (target - eye).normalized();
  const Vec3 x = z.cross(up).normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, z.cross(x), z;
  T.translation() = eye;
  return T;
}

struct DepthCamera {
  PinholeIntrinsics intrinsics;
  Eigen::Isometry3d pose;  // T_world_camera
  int width = 0, height = 0;
};

// Looks at the clamped foam bar (scenes/foam_bar_clamped.json, 32 cm along x) from the front,
// above and to the side: its −y side and its top, ~3,000 pixels on it.
inline DepthCamera bar_camera() {
  return {{300, 300, 129.5, 59.5}, look_at(Vec3(0.02, -0.35, 0.25), Vec3(0, 0, -0.02)), 260, 120};
}

// What `camera` sees of the surface at `positions`: SimulatedCamera::depth_image with noise σ
// along each ray and `outlier_fraction` of the pixels on the object flying.
inline DepthImage seen_depth(const DepthCamera& camera, const TetMesh& mesh,
                             const Positions& positions, double sigma, double outlier_fraction,
                             std::mt19937& rng) {
  SimulatedCamera simulated;
  simulated.sigma = sigma;
  simulated.outlier_fraction = outlier_fraction;
  return simulated.depth_image(mesh, positions, camera.intrinsics, camera.pose, camera.width,
                               camera.height, rng);
}

// A frame's "depth_image" for `camera`'s image in `file` (16-bit units of `scale` m).
inline nlohmann::json depth_image_json(const DepthCamera& camera, const std::string& file,
                                       double scale) {
  const PinholeIntrinsics& k = camera.intrinsics;
  return {{"file", file},
          {"scale", scale},
          {"intrinsics", {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}}},
          {"camera_pose", scene_pose_json(camera.pose)}};
}

}  // namespace shapectl::test
