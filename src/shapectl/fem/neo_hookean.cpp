#include <shapectl/fem/neo_hookean.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <shapectl/hand_off.hpp>

namespace shapectl {

namespace {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat34 = Eigen::Matrix<double, 3, 4>;

Vec12 gather(const Positions& x, const TetRest& t) {
  Vec12 xe;
  for (int a = 0; a < 4; ++a) xe.segment<3>(3 * a) = x.segment<3>(3 * t.nodes[a]);
  return xe;
}

// How each node enters F = Ds Dm⁻¹ (Ds = [x1−x0, x2−x0, x3−x0]): ∂F/∂x_a = (·) ⊗ b(:, a), so
// the force on node a is V P b(:, a) and a Hessian block couples b(:, a) and b(:, c).
Mat34 shape_gradients(const Mat3& Dm_inverse) {
  Mat34 b;
  b.rightCols<3>() = Dm_inverse.transpose();
  b.col(0) = -b.rightCols<3>().rowwise().sum();
  return b;
}

void clamp_negative_eigenvalues(Mat9& C) {
  Eigen::SelfAdjointEigenSolver<Mat9> eig(C);
  const auto values = eig.eigenvalues().cwiseMax(0.0);
  C = eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
}

// V ∂²Ψ/∂x² of one tet from F⁻ᵀ, ln J and the shape gradients b. Kept out of line: inlined,
// its 9 × 9 and 9 × 12 temporaries gave the energy and gradient path a 5 kB stack frame and
// spills around the log call (a third of the gradient's time).
[[gnu::noinline]] void tet_hessian(const TetRest& rest, const Material& m, const Mat3& F_inv_T,
                                   double log_J, const Mat34& b, bool project_psd, Mat12& hessian) {
  // dP = μ dF + (μ − κ ln J) F⁻ᵀ dFᵀ F⁻ᵀ + κ tr(F⁻¹dF) F⁻ᵀ
  const Mat3& G = F_inv_T;
  const double c = m.mu - m.kappa * log_J;
  if (!project_psd) {
    // With dF = dx_b b_bᵀ and f_a = V P b_a, each term of dP gives a 3 × 3 block in closed
    // form, u = G b: H_ab = V (μ (b_a·b_b) I + κ u_a u_bᵀ + c u_b u_aᵀ). A fifth of the flops
    // of V Bᵀ C B below.
    const Mat34 u = G * b;
    const Eigen::Matrix4d dots = b.transpose() * b;
    const double V = rest.volume;
    for (int a = 0; a < 4; ++a)
      for (int n = 0; n <= a; ++n) {
        Mat3 block = (V * m.kappa) * u.col(a) * u.col(n).transpose() +
                     (V * c) * u.col(n) * u.col(a).transpose();
        block.diagonal().array() += V * m.mu * dots(a, n);
        hessian.block<3, 3>(3 * a, 3 * n) = block;
        hessian.block<3, 3>(3 * n, 3 * a) = block.transpose();
      }
    return;
  }
  // Projected: the 9 × 9 ∂P/∂F, C, with its negative eigenvalues clamped, then V Bᵀ C B.
  Mat9 C = m.mu * Mat9::Identity();
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> g(G.data());
  C += m.kappa * g * g.transpose();
  // ∂(F⁻ᵀ dFᵀ F⁻ᵀ)_ij / ∂F_lk = G_ik G_lj
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) C(3 * j + i, 3 * k + l) += c * G(i, k) * G(l, j);
  clamp_negative_eigenvalues(C);
  // B = ∂vec(F)/∂x, with B's structure B(3j+i, 3a+i) = b(j, a) used directly: a third of the
  // flops of the dense product.
  Eigen::Matrix<double, 9, 12> CB;  // C B
  for (int n = 0; n < 4; ++n)
    for (int k = 0; k < 3; ++k)
      for (int r = 0; r < 9; ++r)
        CB(r, 3 * n + k) = C(r, k) * b(0, n) + C(r, 3 + k) * b(1, n) + C(r, 6 + k) * b(2, n);
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int col = 0; col < 12; ++col)
        hessian(3 * a + i, col) = rest.volume * (b(0, a) * CB(i, col) + b(1, a) * CB(3 + i, col) +
                                                 b(2, a) * CB(6 + i, col));
}

constexpr std::size_t kGrain = 64;

void append_tets(const TetMesh& mesh, ElementNodes& elements) {
  for (const auto& t : mesh.tets()) elements.add({t.nodes[0], t.nodes[1], t.nodes[2], t.nodes[3]});
}

ElementNodes tet_nodes(const TetMesh& mesh) {
  ElementNodes elements;
  append_tets(mesh, elements);
  return elements;
}

// neo_hookean_tet's body, inlined into each caller so that the energy-only calls (value) compile
// without the derivative branches.
[[gnu::always_inline]] inline double tet_kernel(const TetRest& rest, const Material& m,
                                                const Vec12& x, double* gradient, Mat12* hessian,
                                                bool project_psd) {
  Mat3 Ds;
  for (int c = 0; c < 3; ++c) Ds.col(c) = x.segment<3>(3 * (c + 1)) - x.segment<3>(0);
  const Mat3 F = Ds * rest.Dm_inverse;
  const double J = F.determinant();
  if (!(J > 0)) return std::numeric_limits<double>::infinity();
  // Whatever needs F is computed before the call to log: across a call the compiler spills F
  // to the stack, and reading it back stalls on store forwarding (this order made the energy
  // kernel 18 % cheaper on the 12k-tet bar).
  const double F_norm2 = F.squaredNorm();
  const bool derivatives = gradient || hessian;
  Mat3 F_inv_T, mu_F;
  if (derivatives) {
    F_inv_T = F.inverse().transpose();
    mu_F = m.mu * F;
  }
  const double log_J = std::log(J);
  const double energy =
      rest.volume * (0.5 * m.mu * (F_norm2 - 3.0) - m.mu * log_J + 0.5 * m.kappa * log_J * log_J);
  if (!derivatives) return energy;

  if (gradient) {
    // P = μ(F − F⁻ᵀ) + κ ln J F⁻ᵀ. With F = Ds Dm⁻¹, the force on node c + 1 is column c of
    // V P Dm⁻ᵀ and node 0's is minus their sum. (Eigen's dense Bᵀ vec(P), 12 × 9 by 9 and
    // mostly zeros, goes through its general matrix-vector routine: 3× this kernel's cost.)
    const Mat3 P = mu_F + (m.kappa * log_J - m.mu) * F_inv_T;
    const Mat3 node_forces = rest.volume * P * rest.Dm_inverse.transpose();
    Eigen::Map<Vec12> g(gradient);
    g.segment<9>(3) = node_forces.reshaped();
    g.segment<3>(0) = -node_forces.rowwise().sum();
  }
  if (hessian)
    tet_hessian(rest, m, F_inv_T, log_J, shape_gradients(rest.Dm_inverse), project_psd, *hessian);
  return energy;
}

// The energy-only and the energy-and-gradient kernels, each compiled for its case. Out of line:
// inlined into a sum, V·Ψ could fuse with the addition (FMA) in one caller and not in another,
// and value() and value_and_add_gradient() would differ in the last bit.
[[gnu::noinline]] double tet_energy(const TetRest& rest, const Material& m, const Vec12& x) {
  return tet_kernel(rest, m, x, nullptr, nullptr, false);
}
[[gnu::noinline]] double tet_energy_gradient(const TetRest& rest, const Material& m, const Vec12& x,
                                             double* gradient) {
  return tet_kernel(rest, m, x, gradient, nullptr, false);
}

}  // namespace

double neo_hookean_tet(const TetRest& rest, const Material& m, const Vec12& x, Vec12* gradient,
                       Mat12* hessian, bool project_psd) {
  return tet_kernel(rest, m, x, gradient ? gradient->data() : nullptr, hessian, project_psd);
}

NeoHookean::NeoHookean(const TetMesh& mesh, const Material& material)
    : NeoHookean(mesh, std::vector<Material>{material}) {}

NeoHookean::NeoHookean(const TetMesh& mesh, std::vector<Material> materials)
    : mesh_(mesh),
      materials_(std::move(materials)),
      stride_(materials_.size() == 1 ? 0 : 1),
      gather_(tet_nodes(mesh), mesh.node_count()) {
  if (materials_.size() != 1 && materials_.size() != mesh.tets().size())
    throw std::invalid_argument("NeoHookean: " + std::to_string(materials_.size()) +
                                " materials for " + std::to_string(mesh.tets().size()) +
                                " elements (expected one, or one per element)");
}

double NeoHookean::value(const Positions& x) const {
  const auto& tets = mesh_.tets();
  HandOff hand_off;
  const double energy = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, tets.size(), kGrain), 0.0,
      hand_off([&](const tbb::blocked_range<std::size_t>& r, double sum) {
        for (std::size_t e = r.begin(); e != r.end(); ++e)
          sum += tet_energy(tets[e], material(e), gather(x, tets[e]));
        return sum;
      }),
      hand_off(std::plus<>()));
  hand_off.joined();
  return energy;
}

// Element e's energy, and its corner gradients into corners[0 … 11] (NaN if it is inverted, so
// the gradient is NaN where the energy is +inf).
double NeoHookean::tet_energy_and_gradient(const Positions& x, std::size_t e,
                                           double* corners) const {
  // Written in place: a local copy, read back as wide loads, stalled on store forwarding.
  const TetRest& tet = mesh_.tets()[e];
  const double energy = tet_energy_gradient(tet, material(e), gather(x, tet), corners);
  if (!std::isfinite(energy))
    Eigen::Map<Vec12>{corners}.setConstant(std::numeric_limits<double>::quiet_NaN());
  return energy;
}

void NeoHookean::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const std::size_t tet_count = mesh_.tets().size();
  const std::unique_ptr<double[]> corners(new double[12 * tet_count]);  // every entry written
  HandOff hand_off;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tet_count, kGrain),
                    hand_off([&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        tet_energy_and_gradient(x, e, &corners[12 * e]);
                    }));
  hand_off.joined();
  gather_.add(corners.get(), gradient);
}

double NeoHookean::value_and_add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  // value()'s reduction (same range, grain and order), so the sum is value()'s bit for bit.
  const std::size_t tet_count = mesh_.tets().size();
  const std::unique_ptr<double[]> corners(new double[12 * tet_count]);  // every entry written
  HandOff hand_off;
  const double energy =
      tbb::parallel_deterministic_reduce(tbb::blocked_range<std::size_t>(0, tet_count, kGrain), 0.0,
                                         hand_off([&](const tbb::blocked_range<std::size_t>& r,
                                                      double sum) {
                                           for (std::size_t e = r.begin(); e != r.end(); ++e)
                                             sum += tet_energy_and_gradient(x, e, &corners[12 * e]);
                                           return sum;
                                         }),
                                         hand_off(std::plus<>()));
  hand_off.joined();
  gather_.add(corners.get(), gradient);
  return energy;
}

void NeoHookean::hessian_elements(const Positions&, ElementNodes& elements) const {
  append_tets(mesh_, elements);
}

void NeoHookean::add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const {
  const auto& tets = mesh_.tets();
  sink.add_blocks([&](std::size_t e, double* block) {
    Mat12 H;
    // An inverted tet leaves its block NaN, so the factorization fails.
    if (std::isfinite(
            neo_hookean_tet(tets[e], material(e), gather(x, tets[e]), nullptr, &H, project_psd)))
      Eigen::Map<Mat12>{block} = H;
  });
}

}  // namespace shapectl
