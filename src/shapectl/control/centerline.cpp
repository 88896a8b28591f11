#include <shapectl/control/centerline.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

std::optional<BarAxis> find_bar_axis(const TetMesh& mesh) {
  const auto& X = mesh.rest_positions();
  BarAxis axis;
  axis.center.setZero();
  for (const auto& p : X) axis.center += p;
  axis.center /= static_cast<double>(X.size());
  Mat3 covariance = Mat3::Zero();
  for (const auto& p : X) covariance += (p - axis.center) * (p - axis.center).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(covariance);
  axis.direction = eig.eigenvectors().col(2);  // largest spread
  double s_max = -1e300;
  axis.s_min = 1e300;
  for (const auto& p : X) {
    const double s = (p - axis.center).dot(axis.direction);
    axis.s_min = std::min(axis.s_min, s);
    s_max = std::max(s_max, s);
  }
  axis.length = s_max - axis.s_min;
  for (int c = 0; c < 2; ++c) {
    double lo = 1e300, hi = -1e300;
    for (const auto& p : X) {
      const double u = (p - axis.center).dot(eig.eigenvectors().col(c));
      lo = std::min(lo, u);
      hi = std::max(hi, u);
    }
    axis.thickness = std::max(axis.thickness, hi - lo);
  }
  if (!(axis.length >= 3 * axis.thickness)) return std::nullopt;

  // Stations about a third of the thickness long; the node nearest the axis in each.
  const int stations =
      std::clamp(static_cast<int>(std::round(3 * axis.length / axis.thickness)), 4, 200);
  std::vector<int> best(stations, -1);
  std::vector<double> best_distance(stations, 1e300);
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Vec3 d = X[i] - axis.center;
    const double s = d.dot(axis.direction);
    const double r = (d - s * axis.direction).norm();
    const int k =
        std::min(stations - 1, static_cast<int>((s - axis.s_min) / axis.length * stations));
    if (r < best_distance[k]) {
      best_distance[k] = r;
      best[k] = i;
    }
  }
  for (int i : best)
    if (i >= 0) axis.centerline_nodes.push_back(i);
  return axis;
}

namespace {
// The sketch without repeated points: points closer than round-off of the bar's size to the
// last one kept are merged (a segment that short would give a tangent of noise).
std::vector<Vec3> distinct_points(const BarAxis& axis, const std::vector<Vec3>& polyline) {
  const double merge = 1e-9 * axis.length;
  std::vector<Vec3> points;
  for (const auto& p : polyline)
    if (points.empty() || (p - points.back()).norm() > merge) points.push_back(p);
  return points;
}
}  // namespace

void check_centerline(const BarAxis& axis, const std::vector<Vec3>& polyline,
                      const std::string& source) {
  for (std::size_t k = 0; k < polyline.size(); ++k)
    check_target_point(polyline[k], source, "centerline[" + std::to_string(k) + "]");
  const std::vector<Vec3> points = distinct_points(axis, polyline);
  double length = 0;
  for (std::size_t k = 1; k < points.size(); ++k) length += (points[k] - points[k - 1]).norm();
  const double shortest = min_centerline_fraction * axis.length;
  if (points.size() < 2 || !(length >= shortest)) {
    std::ostringstream need, found;
    need << "a polyline of at least 2 distinct points, at least " << shortest << " m long ("
         << min_centerline_fraction << " × the bar's length)";
    found << points.size() << " distinct points, " << length << " m long";
    throw InputError(source, "centerline", need.str(), found.str());
  }
}

ShapeTargets centerline_targets(const TetMesh& mesh, const BarAxis& axis,
                                const std::vector<Vec3>& polyline, const Positions& x) {
  check_centerline(axis, polyline, "centerline");
  const std::vector<Vec3> points = distinct_points(axis, polyline);
  std::vector<double> arc(points.size(), 0.0);
  for (std::size_t k = 1; k < points.size(); ++k)
    arc[k] = arc[k - 1] + (points[k] - points[k - 1]).norm();
  const double total = arc.back();
  auto at = [&](double length, Vec3* tangent) {
    const auto it = std::upper_bound(arc.begin(), arc.end(), length);
    const std::size_t k = std::clamp<std::size_t>(it - arc.begin(), 1, points.size() - 1);
    const double segment = arc[k] - arc[k - 1];
    const double w = std::clamp((length - arc[k - 1]) / segment, 0.0, 1.0);
    *tangent = (points[k] - points[k - 1]) / segment;
    return Vec3((1 - w) * points[k - 1] + w * points[k]);
  };
  // Which bar end goes to the sketch's start: the one currently nearer to it.
  const int first = axis.centerline_nodes.front(), last = axis.centerline_nodes.back();
  const bool reversed = (x.segment<3>(3 * last) - points.front()).norm() <
                        (x.segment<3>(3 * first) - points.front()).norm();
  ShapeTargets targets;
  for (int i : axis.centerline_nodes) {
    const Vec3 d = mesh.rest_positions()[i] - axis.center;
    const double s = d.dot(axis.direction);
    double t = (s - axis.s_min) / axis.length;
    if (reversed) t = 1 - t;
    Vec3 tangent;
    const Vec3 c = at(t * total, &tangent);
    const Vec3 rest_tangent = reversed ? Vec3(-axis.direction) : axis.direction;
    const Vec3 offset = d - s * axis.direction;
    targets.nodes.push_back(i);
    targets.positions.push_back(c +
                                Eigen::Quaterniond::FromTwoVectors(rest_tangent, tangent) * offset);
  }
  return targets;
}

}  // namespace shapectl
