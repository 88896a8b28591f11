#pragma once
// The distance between two points, with derivatives with respect to those that vary.
#include <shapectl/contact/distance_piece.hpp>

namespace shapectl {

// |p − q|; gradient and Hessian (may be null) with respect to the coordinates of the points
// with varies[k] (p first): N = 3 × their count.
template <int N>
double point_point_distance(const Vec3& p, const Vec3& q, const std::array<bool, 2>& varies,
                            VecN<N>* gradient = nullptr, MatN<N>* hessian = nullptr) {
  return contact::evaluate_piece<N>(
      [](const auto& P) { return contact::point_point_piece(P[0], P[1]); },
      std::array<Vec3, 2>{p, q}, varies, gradient, hessian);
}

}  // namespace shapectl
