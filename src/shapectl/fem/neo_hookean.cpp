#include <shapectl/fem/neo_hookean.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace shapectl {

namespace {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat9x12 = Eigen::Matrix<double, 9, 12>;

Vec12 gather(const Positions& x, const TetRest& t) {
  Vec12 xe;
  for (int a = 0; a < 4; ++a) xe.segment<3>(3 * a) = x.segment<3>(3 * t.nodes[a]);
  return xe;
}

// ∂vec(F)/∂x (column-major vec), using F = Ds Dm⁻¹ with Ds = [x1−x0, x2−x0, x3−x0].
Mat9x12 dF_dx(const Mat3& Dm_inverse) {
  Eigen::Matrix<double, 3, 4> b;  // b(:, a): how node a enters each column of F
  b.rightCols<3>() = Dm_inverse.transpose();
  b.col(0) = -b.rightCols<3>().rowwise().sum();
  Mat9x12 B = Mat9x12::Zero();
  for (int a = 0; a < 4; ++a)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) B(3 * j + i, 3 * a + i) = b(j, a);
  return B;
}

void clamp_negative_eigenvalues(Mat9& C) {
  Eigen::SelfAdjointEigenSolver<Mat9> eig(C);
  const auto values = eig.eigenvalues().cwiseMax(0.0);
  C = eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
}

constexpr std::size_t kGrain = 64;

}  // namespace

double neo_hookean_tet(const TetRest& rest, const Material& m, const Vec12& x, Vec12* gradient,
                       Mat12* hessian, bool project_psd) {
  Mat3 Ds;
  for (int c = 0; c < 3; ++c) Ds.col(c) = x.segment<3>(3 * (c + 1)) - x.segment<3>(0);
  const Mat3 F = Ds * rest.Dm_inverse;
  const double J = F.determinant();
  if (!(J > 0)) return std::numeric_limits<double>::infinity();
  const double log_J = std::log(J);
  const double psi =
      0.5 * m.mu * (F.squaredNorm() - 3.0) - m.mu * log_J + 0.5 * m.kappa * log_J * log_J;
  if (!gradient && !hessian) return rest.volume * psi;

  const Mat3 F_inv_T = F.inverse().transpose();
  if (gradient) {
    const Mat9x12 B = dF_dx(rest.Dm_inverse);
    // P = μ(F − F⁻ᵀ) + κ ln J F⁻ᵀ
    const Mat3 P = m.mu * (F - F_inv_T) + m.kappa * log_J * F_inv_T;
    *gradient =
        rest.volume * B.transpose() * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(P.data());
  }
  if (hessian) {
    // dP = μ dF + (μ − κ ln J) F⁻ᵀ dFᵀ F⁻ᵀ + κ tr(F⁻¹dF) F⁻ᵀ
    const Mat3& G = F_inv_T;
    const double c = m.mu - m.kappa * log_J;
    Mat9 C = m.mu * Mat9::Identity();
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> g(G.data());
    C += m.kappa * g * g.transpose();
    // ∂(F⁻ᵀ dFᵀ F⁻ᵀ)_ij / ∂F_lk = G_ik G_lj
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) C(3 * j + i, 3 * k + l) += c * G(i, k) * G(l, j);
    if (project_psd) clamp_negative_eigenvalues(C);
    // H = V Bᵀ C B with B's structure B(3j+i, 3a+i) = b(j, a) used directly: a third of the
    // flops of the dense product.
    Eigen::Matrix<double, 3, 4> b;
    b.rightCols<3>() = rest.Dm_inverse.transpose();
    b.col(0) = -b.rightCols<3>().rowwise().sum();
    Eigen::Matrix<double, 9, 12> CB;  // C B
    for (int n = 0; n < 4; ++n)
      for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 9; ++r)
          CB(r, 3 * n + k) = C(r, k) * b(0, n) + C(r, 3 + k) * b(1, n) + C(r, 6 + k) * b(2, n);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i)
        for (int col = 0; col < 12; ++col)
          (*hessian)(3 * a + i, col) =
              rest.volume *
              (b(0, a) * CB(i, col) + b(1, a) * CB(3 + i, col) + b(2, a) * CB(6 + i, col));
  }
  return rest.volume * psi;
}

double NeoHookean::value(const Positions& x) const {
  const auto& tets = mesh_.tets();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, tets.size(), kGrain), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double sum) {
        for (std::size_t e = r.begin(); e != r.end(); ++e)
          sum += neo_hookean_tet(tets[e], material_, gather(x, tets[e]));
        return sum;
      },
      std::plus<>());
}

void NeoHookean::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const auto& tets = mesh_.tets();
  std::vector<Vec12> per_tet(tets.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tets.size(), kGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        per_tet[e].setConstant(std::numeric_limits<double>::quiet_NaN());
                        neo_hookean_tet(tets[e], material_, gather(x, tets[e]), &per_tet[e]);
                      }
                    });
  // Serial scatter: nodes are shared between tets.
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (int a = 0; a < 4; ++a)
      gradient.segment<3>(3 * tets[e].nodes[a]) += per_tet[e].segment<3>(3 * a);
}

void NeoHookean::hessian_elements(ElementNodes& elements) const {
  for (const auto& t : mesh_.tets()) elements.add({t.nodes[0], t.nodes[1], t.nodes[2], t.nodes[3]});
}

void NeoHookean::add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const {
  const auto& tets = mesh_.tets();
  sink.add_blocks([&](std::size_t e, double* block) {
    Mat12 H;
    // An inverted tet leaves its block NaN, so the factorization fails.
    if (std::isfinite(
            neo_hookean_tet(tets[e], material_, gather(x, tets[e]), nullptr, &H, project_psd)))
      Eigen::Map<Mat12>{block} = H;
  });
}

}  // namespace shapectl
