#include <shapectl/calib/simulated_camera.hpp>

#include <cmath>

#include <Eigen/Geometry>

#include <shapectl/calib/depth_render.hpp>

namespace shapectl {

ObservationFrame SimulatedCamera::observe(const TetMesh& mesh, const Positions& positions,
                                          const Eigen::VectorXd& joints, std::mt19937& rng) const {
  std::normal_distribution<double> noise(0, sigma);
  auto noisy = [&](const Vec3& p) { return Vec3(p + Vec3(noise(rng), noise(rng), noise(rng))); };
  ObservationFrame frame;
  frame.joints = joints;
  frame.sigma = sigma;
  for (int node : marker_nodes)
    frame.markers.push_back({node, noisy(positions.segment<3>(3 * node))});
  if (surface_points <= 0) return frame;

  // Triangles drawn in proportion to their area, points uniform inside.
  const auto triangles = mesh.surface_triangles();
  std::vector<double> areas;
  Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const auto& t : triangles) {
    const Vec3 a = positions.segment<3>(3 * t[0]), b = positions.segment<3>(3 * t[1]),
               c = positions.segment<3>(3 * t[2]);
    areas.push_back(0.5 * (b - a).cross(c - a).norm());
    lo = lo.cwiseMin(a).cwiseMin(b).cwiseMin(c);
    hi = hi.cwiseMax(a).cwiseMax(b).cwiseMax(c);
  }
  std::discrete_distribution<std::size_t> pick(areas.begin(), areas.end());
  std::uniform_real_distribution<double> unit(0, 1);
  const int outliers = static_cast<int>(std::lround(outlier_fraction * surface_points));
  for (int k = 0; k < surface_points - outliers; ++k) {
    const auto& t = triangles[pick(rng)];
    double u = unit(rng), v = unit(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Vec3 p = (1 - u - v) * positions.segment<3>(3 * t[0]) +
                   u * positions.segment<3>(3 * t[1]) + v * positions.segment<3>(3 * t[2]);
    frame.points.push_back(noisy(p));
  }
  const Vec3 margin = Vec3::Constant(outlier_margin);
  for (int k = 0; k < outliers; ++k) {
    const Vec3 r(unit(rng), unit(rng), unit(rng));
    frame.points.push_back(lo - margin + r.cwiseProduct(hi - lo + 2 * margin));
  }
  return frame;
}

DepthImage SimulatedCamera::depth_image(const TetMesh& mesh, const Positions& positions,
                                        const PinholeIntrinsics& intrinsics,
                                        const Eigen::Isometry3d& T_world_camera, int width,
                                        int height, std::mt19937& rng) const {
  DepthImage image = render_depth(mesh, positions, intrinsics, T_world_camera, width, height);
  std::normal_distribution<double> noise(0, sigma);
  std::uniform_real_distribution<double> unit(0, 1);
  for (double& z : image.depth) {
    if (std::isnan(z)) continue;
    z = unit(rng) < outlier_fraction ? z * (0.5 + unit(rng)) : z + noise(rng);
  }
  return image;
}

}  // namespace shapectl
