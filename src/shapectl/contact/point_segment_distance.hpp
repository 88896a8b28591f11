#pragma once
// The distance from a point to a segment, classified as IPC does: the closest point is an end
// (point–point) or inside (point–edge); each case is smooth on its own.
#include <shapectl/contact/distance_piece.hpp>

namespace shapectl {

enum class PointSegmentRegion { A, B, Interior };  // the closest point of segment ab

// Where on segment ab the point closest to p lies; its parameter in [0, 1] if t is not null.
PointSegmentRegion point_segment_region(const Vec3& p, const Vec3& a, const Vec3& b,
                                        double* t = nullptr);

// The distance from p to segment ab; gradient and Hessian (may be null) with respect to the
// coordinates of the points with varies[k] (order p, a, b): N = 3 × their count.
template <int N>
double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b,
                              const std::array<bool, 3>& varies, VecN<N>* gradient = nullptr,
                              MatN<N>* hessian = nullptr) {
  using namespace contact;
  const std::array<Vec3, 3> points{p, a, b};
  switch (point_segment_region(p, a, b)) {
    case PointSegmentRegion::A:
      return evaluate_piece<N>([](const auto& P) { return point_point_piece(P[0], P[1]); }, points,
                               varies, gradient, hessian);
    case PointSegmentRegion::B:
      return evaluate_piece<N>([](const auto& P) { return point_point_piece(P[0], P[2]); }, points,
                               varies, gradient, hessian);
    case PointSegmentRegion::Interior: break;
  }
  return evaluate_piece<N>([](const auto& P) { return point_line_piece(P[0], P[1], P[2]); }, points,
                           varies, gradient, hessian);
}

}  // namespace shapectl
