#pragma once
// IPC's edge–edge mollifier (Li et al. 2020, Sec. 4.3): an edge–edge pair's barrier is
// multiplied by
//   e(c) = −c²/ε² + 2c/ε for c < ε,  1 beyond,   c = |(a1 − a0) × (b1 − b0)|²,
// ε = 10⁻³ |a1 − a0|²|b1 − b0|² at rest. As the edges turn parallel (c → 0) the pair's energy
// fades to 0 (the vertex–triangle pairs hold such edges apart), so it stays smooth where the
// closest points leave the edges' insides and the line–line distance's derivatives, which
// grow as 1/sin of the angle, never show. e is C¹ at c = ε (e′(ε) = 0), C² elsewhere.
#include <shapectl/contact/distance_piece.hpp>

namespace shapectl::contact {

// ε for edges of rest lengths² la2, lb2.
inline double edge_mollifier_threshold(double la2, double lb2) { return 1e-3 * la2 * lb2; }

// e(c) of the edges a0–a1 and b0–b1 (p = {a0, a1, b0, b1}), with its gradient and Hessian (may
// be null) with respect to the points with varies[k], as evaluate_piece.
template <int N>
double edge_mollifier(const std::array<Vec3, 4>& p, const std::array<bool, 4>& varies,
                      double threshold, VecN<N>* gradient, MatN<N>* hessian) {
  // Most pairs are far from parallel: 1, no jets.
  if (!(((p[1] - p[0]).cross(p[3] - p[2])).squaredNorm() < threshold)) {
    if (gradient) gradient->setZero();
    if (hessian) hessian->setZero();
    return 1;
  }
  const auto piece = [threshold](const auto& P) {
    using T = std::decay_t<decltype(P[0][0])>;
    const V3<T> n = cross(P[1] - P[0], P[3] - P[2]);
    const T c = dot(n, n);
    return c * (T(2 / threshold) - (1 / (threshold * threshold)) * c);
  };
  return evaluate_piece<N>(piece, p, varies, gradient, hessian);
}

}  // namespace shapectl::contact
