#pragma once
// The distance between two segments, classified as IPC does: the closest points are inside both
// (edge–edge: the lines' distance), an end of one and inside the other (point–edge), or ends of
// both (point–point); each case is smooth on its own.
#include <shapectl/contact/distance_piece.hpp>

namespace shapectl {

// The closest points a0 + s (a1 − a0) and b0 + t (b1 − b0), s, t ∈ [0, 1]: each at an end
// (s = 0 or 1) or inside. Parallel segments get an end (their distance is reached there).
struct SegmentSegmentClosest {
  double s = 0, t = 0;
  bool s_inside = false, t_inside = false;
};
SegmentSegmentClosest segment_segment_closest(const Vec3& a0, const Vec3& a1, const Vec3& b0,
                                              const Vec3& b1);

// The distance between segments a0a1 and b0b1; gradient and Hessian (may be null) with respect
// to the coordinates of the points with varies[k] (order a0, a1, b0, b1): N = 3 × their count.
template <int N>
double segment_segment_distance(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                                const std::array<bool, 4>& varies, VecN<N>* gradient = nullptr,
                                MatN<N>* hessian = nullptr) {
  using namespace contact;
  const std::array<Vec3, 4> points{a0, a1, b0, b1};
  const SegmentSegmentClosest closest = segment_segment_closest(a0, a1, b0, b1);
  const int i = closest.s < 0.5 ? 0 : 1;  // the end of a, if it is one
  const int j = closest.t < 0.5 ? 2 : 3;  // the end of b, if it is one
  const auto run = [&](const auto& piece) {
    return evaluate_piece<N>(piece, points, varies, gradient, hessian);
  };
  if (closest.s_inside && closest.t_inside)
    return run([](const auto& P) { return line_line_piece(P[0], P[1], P[2], P[3]); });
  if (closest.s_inside)
    return run([j](const auto& P) { return point_line_piece(P[j], P[0], P[1]); });
  if (closest.t_inside)
    return run([i](const auto& P) { return point_line_piece(P[i], P[2], P[3]); });
  return run([i, j](const auto& P) { return point_point_piece(P[i], P[j]); });
}

}  // namespace shapectl
