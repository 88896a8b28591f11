#include <shapectl/calib/observation_residuals.hpp>

#include <algorithm>

namespace shapectl {

double outlier_cutoff(const ObservationFrame& frame, const SurfaceDistance& surface,
                      const CameraMotion& camera) {
  if (frame.points.empty()) return 0;
  std::vector<double> d;
  d.reserve(frame.points.size());
  for (const Vec3& p : frame.points) d.push_back(surface.closest(camera.motion * p).distance);
  auto middle = d.begin() + d.size() / 2;
  std::nth_element(d.begin(), middle, d.end());
  // A cloud mostly of background (no crop) puts the median on the background: capped, a point
  // a quarter of the object's size from it is never the object, however far the model is off.
  const double robust = std::min(3 * 1.4826 * *middle, 0.25 * surface.diagonal());
  return std::max(4 * frame.sigma, robust);
}

FrameResiduals frame_residuals(const ObservationFrame& frame, const Positions& x,
                               const SurfaceDistance& surface, double cutoff,
                               const Eigen::MatrixXd& dx_dz, const CameraMotion& camera) {
  const bool with_jacobian = dx_dz.size() > 0;
  const double w = 1 / frame.sigma;
  std::vector<std::pair<Vec3, SurfaceHit>> inliers;
  FrameResiduals out;
  for (const Vec3& observed : frame.points) {
    const Vec3 p = camera.motion * observed;
    const SurfaceHit hit = surface.closest(p);
    if (hit.distance <= cutoff) inliers.emplace_back(p, hit);
    else out.outlier_cost += 0.5 * cutoff * cutoff * w * w;
  }
  const int rows = 3 * static_cast<int>(frame.markers.size()) + static_cast<int>(inliers.size());
  out.residuals.resize(rows);
  if (with_jacobian) out.jacobian.resize(rows, dx_dz.cols());
  int row = 0;
  for (const ObservedMarker& m : frame.markers) {
    const Vec3 error = x.segment<3>(3 * m.node) - m.position;
    out.residuals.segment<3>(row) = w * error;
    if (with_jacobian) out.jacobian.middleRows(row, 3) = w * dx_dz.middleRows(3 * m.node, 3);
    out.sum_squared_error += error.squaredNorm();
    row += 3;
  }
  for (const auto& [p, hit] : inliers) {
    out.residuals[row] = w * hit.distance;
    out.sum_squared_error += hit.distance * hit.distance;
    if (with_jacobian) {
      out.jacobian.row(row).setZero();
      if (hit.distance > 0) {  // on the surface the distance has no direction: no pull
        const Vec3 u = (p - hit.point) / hit.distance;
        for (int k = 0; k < 3; ++k)
          out.jacobian.row(row) -=
              w * hit.barycentric[k] * u.transpose() * dx_dz.middleRows(3 * hit.nodes[k], 3);
        if (camera.column >= 0) {
          out.jacobian.row(row).segment<3>(camera.column) += w * u.transpose();
          out.jacobian.row(row).segment<3>(camera.column + 3) +=
              w * (p - camera.origin).cross(u).transpose();
        }
      }
    }
    ++row;
  }
  out.inlier_points = static_cast<int>(inliers.size());
  out.observation_count = static_cast<int>(frame.markers.size()) + out.inlier_points;
  return out;
}

}  // namespace shapectl
