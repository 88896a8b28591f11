#pragma once
// The distance from a point to a triangle, classified as IPC does: the closest point is a
// corner (point–point), on an edge (point–edge) or inside (point–plane); each case is smooth on
// its own, and together they give the exact distance.
#include <shapectl/contact/distance_piece.hpp>

namespace shapectl {

// Where on triangle abc the point closest to p lies.
enum class PointTriangleRegion { A, B, C, AB, BC, CA, Face };

// The region, and the closest point itself if `closest` is not null.
PointTriangleRegion point_triangle_region(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c, Vec3* closest = nullptr);

// The distance from p to triangle abc (non-degenerate); gradient and Hessian (may be null) with
// respect to the coordinates of the points with varies[k] (order p, a, b, c): N = 3 × their
// count.
template <int N>
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                               const std::array<bool, 4>& varies, VecN<N>* gradient = nullptr,
                               MatN<N>* hessian = nullptr) {
  using namespace contact;
  const std::array<Vec3, 4> points{p, a, b, c};
  const auto corner = [&](auto k) {
    return evaluate_piece<N>(
        [](const auto& P) { return point_point_piece(P[0], P[decltype(k)::value]); }, points,
        varies, gradient, hessian);
  };
  const auto edge = [&](auto i, auto j) {
    return evaluate_piece<N>(
        [](const auto& P) {
          return point_line_piece(P[0], P[decltype(i)::value], P[decltype(j)::value]);
        },
        points, varies, gradient, hessian);
  };
  using One = std::integral_constant<int, 1>;
  using Two = std::integral_constant<int, 2>;
  using Three = std::integral_constant<int, 3>;
  switch (point_triangle_region(p, a, b, c)) {
    case PointTriangleRegion::A: return corner(One());
    case PointTriangleRegion::B: return corner(Two());
    case PointTriangleRegion::C: return corner(Three());
    case PointTriangleRegion::AB: return edge(One(), Two());
    case PointTriangleRegion::BC: return edge(Two(), Three());
    case PointTriangleRegion::CA: return edge(Three(), One());
    case PointTriangleRegion::Face: break;
  }
  return evaluate_piece<N>([](const auto& P) { return point_plane_piece(P[0], P[1], P[2], P[3]); },
                           points, varies, gradient, hessian);
}

}  // namespace shapectl
