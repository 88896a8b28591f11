#pragma once
// The smooth pieces the unsigned distances between points, segments and triangles are made of
// (IPC's point–point, point–edge, point–plane and edge–edge), each written once on any scalar,
// and their evaluation with exact derivatives with respect to the points that vary.
#include <array>
#include <cassert>

#include <shapectl/contact/jet.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

template <int N>
using VecN = Eigen::Matrix<double, N, 1>;
template <int N>
using MatN = Eigen::Matrix<double, N, N>;

namespace contact {

// |p − a|.
template <class T>
T point_point_piece(const V3<T>& p, const V3<T>& a) {
  const V3<T> d = p - a;
  return sqrt(dot(d, d));
}

// The distance from p to the line through a and b.
template <class T>
T point_line_piece(const V3<T>& p, const V3<T>& a, const V3<T>& b) {
  const V3<T> c = cross(a - p, b - p);
  const V3<T> e = b - a;
  return sqrt(dot(c, c) / dot(e, e));
}

// The distance from p to the plane through a, b and c.
template <class T>
T point_plane_piece(const V3<T>& p, const V3<T>& a, const V3<T>& b, const V3<T>& c) {
  const V3<T> n = cross(b - a, c - a);
  const T h = dot(p - a, n);
  return sqrt(h * h / dot(n, n));
}

// The distance between the line through a0, a1 and the line through b0, b1 (not parallel).
template <class T>
T line_line_piece(const V3<T>& a0, const V3<T>& a1, const V3<T>& b0, const V3<T>& b1) {
  const V3<T> n = cross(a1 - a0, b1 - b0);
  const T h = dot(b0 - a0, n);
  return sqrt(h * h / dot(n, n));
}

// piece(P) with P the K points as scalars of the right kind; its gradient and Hessian (either
// may be null) with respect to the coordinates of the points with varies[k], in point order:
// N = 3 × their count.
template <int N, std::size_t K, class Piece>
double evaluate_piece(const Piece& piece, const std::array<Vec3, K>& points,
                      const std::array<bool, K>& varies, VecN<N>* gradient, MatN<N>* hessian) {
  const auto run = [&](auto zero) {
    using T = decltype(zero);
    std::array<V3<T>, K> P;
    int next = 0;
    for (std::size_t k = 0; k < K; ++k) {
      P[k] = lift<T>(points[k], varies[k] ? next : -1);
      if (varies[k]) next += 3;
    }
    assert((next == N || std::is_same_v<T, double>));
    return piece(P);
  };
  if (hessian) {
    const auto j = run(Jet<N, true>());
    if (gradient) *gradient = j.g;
    *hessian = j.h;
    return j.v;
  }
  if (gradient) {
    const auto j = run(Jet<N, false>());
    *gradient = j.g;
    return j.v;
  }
  return run(0.0);
}

}  // namespace contact
}  // namespace shapectl
