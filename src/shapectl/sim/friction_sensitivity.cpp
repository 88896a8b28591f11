#include <shapectl/sim/friction_sensitivity.hpp>

#include <Eigen/QR>
#include <stdexcept>
#include <string>
#include <vector>

#include <shapectl/contact/friction_lag.hpp>

namespace shapectl {

namespace {

// Relative to |H⁻¹ b|: the sensitivities' round-off, far below any derivative check's tolerance.
constexpr double kTolerance = 1e-12;
constexpr int kMaxIterations = 200;

// x with (I + H⁻¹L) x = c, GMRES from x₀ = c (the frictionless-lag answer), no restarts.
Eigen::VectorXd gmres(const StaticsSolver& solver, const StaticsWorkspace& ws,
                      const SparseMatrix& lag, const Eigen::VectorXd& c) {
  const auto apply = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return v + solver.solve_with_factor(ws, lag * v).col(0);
  };
  const double target = kTolerance * c.norm();
  const Eigen::VectorXd r0 = c - apply(c);
  const double beta = r0.norm();
  if (beta <= target) return c;
  std::vector<Eigen::VectorXd> basis{r0 / beta};
  Eigen::MatrixXd hessenberg = Eigen::MatrixXd::Zero(kMaxIterations + 1, kMaxIterations);
  double residual = beta;
  for (int j = 0; j < kMaxIterations; ++j) {
    Eigen::VectorXd w = apply(basis[j]);
    for (int i = 0; i <= j; ++i) {  // modified Gram–Schmidt
      hessenberg(i, j) = basis[i].dot(w);
      w -= hessenberg(i, j) * basis[i];
    }
    hessenberg(j + 1, j) = w.norm();
    const Eigen::MatrixXd h = hessenberg.topLeftCorner(j + 2, j + 1);
    Eigen::VectorXd e1 = Eigen::VectorXd::Zero(j + 2);
    e1[0] = beta;
    const Eigen::VectorXd coefficients = h.colPivHouseholderQr().solve(e1);
    residual = (e1 - h * coefficients).norm();
    if (residual <= target || hessenberg(j + 1, j) == 0) {
      Eigen::VectorXd x = c;
      for (int i = 0; i <= j; ++i) x += coefficients[i] * basis[i];
      return x;
    }
    basis.push_back(w / hessenberg(j + 1, j));
  }
  throw std::runtime_error("sensitivity with friction: GMRES left a residual of " +
                           std::to_string(residual / c.norm()) + " of the solution after " +
                           std::to_string(kMaxIterations) + " solves");
}

}  // namespace

FixedPointFriction fixed_point_friction(const ObstacleContact& contact,
                                        const FrictionSettings& settings, const Positions& anchor,
                                        const Positions& x) {
  const std::vector<ContactPairDerivatives> jets = contact.pair_derivatives(x);
  std::vector<ContactPair> pairs;
  for (const ContactPairDerivatives& p : jets) pairs.push_back(p.pair);
  const Triplets t = friction_lag_jacobian(jets, anchor, x, settings.coefficient, settings.slip);
  SparseMatrix lag(x.size(), x.size());
  lag.setFromTriplets(t.begin(), t.end());
  return {ObstacleFriction(contact, std::move(pairs), anchor, settings.coefficient, settings.slip),
          std::move(lag)};
}

Eigen::MatrixXd solve_with_lag(const StaticsSolver& solver, const StaticsWorkspace& ws,
                               const SparseMatrix& lag, const Eigen::MatrixXd& rhs) {
  Eigen::MatrixXd x = solver.solve_with_factor(ws, rhs);  // H⁻¹ b: the right side and x₀
  for (Eigen::Index k = 0; k < x.cols(); ++k)
    if (x.col(k).norm() > 0) x.col(k) = gmres(solver, ws, lag, x.col(k));
  return x;
}

}  // namespace shapectl
