#include <shapectl/contact/friction.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace shapectl {

double friction_mollifier(double y, double slip) {
  return y < slip ? -y * y * y / (3 * slip * slip) + y * y / slip + slip / 3 : y;
}

double friction_mollifier_slope_over_y(double y, double slip) {
  return y < slip ? 2 / slip - y / (slip * slip) : 1 / y;
}

ObstacleFriction::ObstacleFriction(const ObstacleContact& contact, std::vector<ContactPair> pairs,
                                   Positions anchor, double coefficient, double slip)
    : pairs_(std::move(pairs)), anchor_(std::move(anchor)), coefficient_(coefficient), slip_(slip) {
  if (!(coefficient >= 0) || !std::isfinite(coefficient))
    throw std::invalid_argument("ObstacleFriction: the coefficient must be non-negative, finite");
  if (!(slip > 0) || !std::isfinite(slip))
    throw std::invalid_argument("ObstacleFriction: the slip length must be positive and finite");
  contact.hessian_elements(anchor_, elements_);  // the surface's, whatever the state
  std::stable_sort(pairs_.begin(), pairs_.end(), [](const ContactPair& a, const ContactPair& b) {
    return a.element < b.element;
  });
  first_.assign(elements_.size() + 1, 0);
  for (const ContactPair& p : pairs_) ++first_[p.element + 1];
  for (std::size_t e = 0; e < elements_.size(); ++e) first_[e + 1] += first_[e];
}

Vec3 ObstacleFriction::slip(const Positions& x, std::size_t k) const {
  const ContactPair& p = pairs_[k];
  Vec3 motion = Vec3::Zero();
  for (int a = 0; a < p.node_count; ++a)
    motion += p.weights[a] * (x.segment<3>(3 * p.nodes[a]) - anchor_.segment<3>(3 * p.nodes[a]));
  return motion - p.normal.dot(motion) * p.normal;
}

double ObstacleFriction::value(const Positions& x) const {
  double sum = 0;
  for (std::size_t k = 0; k < pairs_.size(); ++k)
    sum += coefficient_ * pairs_[k].force * friction_mollifier(slip(x, k).norm(), slip_);
  return sum;
}

void ObstacleFriction::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const ContactPair& p = pairs_[k];
    const Vec3 u = slip(x, k);
    // ∂D/∂u = μλ f₁(y) u/y (in the tangent plane already).
    const Vec3 g = coefficient_ * p.force * friction_mollifier_slope_over_y(u.norm(), slip_) * u;
    for (int a = 0; a < p.node_count; ++a) gradient.segment<3>(3 * p.nodes[a]) += p.weights[a] * g;
  }
}

void ObstacleFriction::hessian_elements(const Positions& /*x*/, ElementNodes& elements) const {
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const int* n = elements_.begin(e);
    switch (elements_.node_count(e)) {
      case 1: elements.add({n[0]}); break;
      case 2: elements.add({n[0], n[1]}); break;
      default: elements.add({n[0], n[1], n[2]});
    }
  }
}

void ObstacleFriction::add_hessian(const Positions& x, ElementHessianSink& sink,
                                   bool /*project_psd*/) const {
  // ∂²D/∂u² = μλ [(f₁/y) P + s ûûᵀ], s = −y/ε² (y < ε) or −1/y (y ≥ ε): eigenvalues f₁/y
  // across û and f₁′ ≥ 0 along it, so PSD as it stands (nothing to project). Node blocks
  // (a, b): wₐ w_b times it.
  sink.add_blocks([&](std::size_t e, double* block) {
    const int dofs = 3 * elements_.node_count(e);
    Eigen::Map<Eigen::MatrixXd> H(block, dofs, dofs);
    H.setZero();
    for (int k = first_[e]; k < first_[e + 1]; ++k) {
      const ContactPair& p = pairs_[k];
      const Vec3 u = slip(x, k);
      const double y = u.norm();
      const Mat3 P = Mat3::Identity() - p.normal * p.normal.transpose();
      Mat3 Hu = friction_mollifier_slope_over_y(y, slip_) * P;
      if (y > 0) Hu -= (y < slip_ ? y / (slip_ * slip_) : 1 / y) / (y * y) * u * u.transpose();
      Hu *= coefficient_ * p.force;
      for (int a = 0; a < p.node_count; ++a)
        for (int b = 0; b < p.node_count; ++b)
          H.block<3, 3>(3 * a, 3 * b) += p.weights[a] * p.weights[b] * Hu;
    }
  });
}

}  // namespace shapectl
