#pragma once
// A forward-mode dual number carrying the value, gradient and (if kHessian) Hessian of a scalar
// with respect to N variables. The distance pieces are written once as templates on their scalar
// and evaluated with double (value), Jet<N, false> (gradient) or Jet<N, true> (Hessian): exact
// derivatives, no hand-expanded Hessians.
#include <array>
#include <cmath>

#include <shapectl/types.hpp>

namespace shapectl::contact {

template <int N, bool kHessian>
struct Jet {
  static constexpr int H = kHessian ? N : 1;  // the Hessian's size (1 × 1, unused, without)
  double v = 0;
  Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();
  Eigen::Matrix<double, H, H> h = Eigen::Matrix<double, H, H>::Zero();

  Jet() = default;
  Jet(double value) : v(value) {}  // a constant
  // Variable i (0 ≤ i < N) with value `value`.
  static Jet variable(double value, int i) {
    Jet j(value);
    j.g[i] = 1;
    return j;
  }
};

template <int N, bool K>
Jet<N, K> operator+(const Jet<N, K>& a, const Jet<N, K>& b) {
  Jet<N, K> r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  if constexpr (K) r.h = a.h + b.h;
  return r;
}

template <int N, bool K>
Jet<N, K> operator-(const Jet<N, K>& a, const Jet<N, K>& b) {
  Jet<N, K> r;
  r.v = a.v - b.v;
  r.g = a.g - b.g;
  if constexpr (K) r.h = a.h - b.h;
  return r;
}

template <int N, bool K>
Jet<N, K> operator*(const Jet<N, K>& a, const Jet<N, K>& b) {
  Jet<N, K> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  if constexpr (K) r.h = a.v * b.h + b.v * a.h + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}

template <int N, bool K>
Jet<N, K> operator*(double s, const Jet<N, K>& a) {
  Jet<N, K> r;
  r.v = s * a.v;
  r.g = s * a.g;
  if constexpr (K) r.h = s * a.h;
  return r;
}

// 1 / a.
template <int N, bool K>
Jet<N, K> reciprocal(const Jet<N, K>& a) {
  Jet<N, K> r;
  const double inv = 1 / a.v;
  r.v = inv;
  r.g = -inv * inv * a.g;
  if constexpr (K) r.h = -inv * inv * a.h + 2 * inv * inv * inv * a.g * a.g.transpose();
  return r;
}

template <int N, bool K>
Jet<N, K> operator/(const Jet<N, K>& a, const Jet<N, K>& b) {
  return a * reciprocal(b);
}

template <int N, bool K>
Jet<N, K> sqrt(const Jet<N, K>& a) {
  Jet<N, K> r;
  r.v = std::sqrt(a.v);
  const double half_inv = 0.5 / r.v;
  r.g = half_inv * a.g;
  if constexpr (K) r.h = half_inv * a.h - (half_inv / a.v) * 0.5 * a.g * a.g.transpose();
  return r;
}

using std::sqrt;

// A 3-vector of any scalar, with the few operations the distances need.
template <class T>
using V3 = std::array<T, 3>;

template <class T>
V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Point p as scalars of type T: constants, or variables first_variable … first_variable + 2
// (first_variable < 0: a constant).
template <class T>
V3<T> lift(const Vec3& p, int first_variable) {
  if constexpr (std::is_same_v<T, double>) {
    return {p[0], p[1], p[2]};
  } else {
    if (first_variable < 0) return {T(p[0]), T(p[1]), T(p[2])};
    return {T::variable(p[0], first_variable), T::variable(p[1], first_variable + 1),
            T::variable(p[2], first_variable + 2)};
  }
}

}  // namespace shapectl::contact
