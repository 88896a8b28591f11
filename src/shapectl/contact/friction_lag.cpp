#include <shapectl/contact/friction_lag.hpp>

#include <shapectl/contact/friction.hpp>

namespace shapectl {

Triplets friction_lag_jacobian(const std::vector<ContactPairDerivatives>& pairs,
                               const Positions& anchor, const Positions& x, double coefficient,
                               double slip) {
  Triplets out;
  using Row = Eigen::Matrix<double, 1, 9>;
  using Block = Eigen::Matrix<double, 3, 9>;
  for (const ContactPairDerivatives& jet : pairs) {
    const ContactPair& p = jet.pair;
    const int K = p.node_count;
    Vec3 v = Vec3::Zero();
    Block moved_weights = Block::Zero();  // Σ_b (x_b − x̄_b) ∂w_b/∂x
    for (int b = 0; b < K; ++b) {
      const Vec3 motion = x.segment<3>(3 * p.nodes[b]) - anchor.segment<3>(3 * p.nodes[b]);
      v += p.weights[b] * motion;
      moved_weights += motion * jet.weights.row(b);
    }
    const Mat3 P = Mat3::Identity() - p.normal * p.normal.transpose();
    const Vec3 u = P * v;
    const double y = u.norm();
    const double slope_over_y = friction_mollifier_slope_over_y(y, slip);
    const Vec3 phi = coefficient * slope_over_y * u;
    Mat3 J = coefficient * slope_over_y * Mat3::Identity();  // ∂φ/∂u, as in add_hessian
    if (y > 0)
      J -= coefficient * (y < slip ? y / (slip * slip) : 1 / y) / (y * y) * u * u.transpose();
    // ∂u/∂x through the lag: P's turn with n and the closest point's move along the element.
    const Block du =
        -p.normal * (v.transpose() * jet.normal) - p.normal.dot(v) * jet.normal + P * moved_weights;
    const Block turn = p.force * J * du;
    for (int a = 0; a < K; ++a) {
      const Row pressed = p.force * jet.weights.row(a) + p.weights[a] * jet.force;
      const Block L = phi * pressed + p.weights[a] * turn;
      for (int c = 0; c < K; ++c)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (L(i, 3 * c + j) != 0)
              out.emplace_back(3 * p.nodes[a] + i, 3 * p.nodes[c] + j, L(i, 3 * c + j));
    }
  }
  return out;
}

}  // namespace shapectl
