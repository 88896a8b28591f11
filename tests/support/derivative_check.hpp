#pragma once
// Checks an energy term's gradient and Hessian against central differences.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/fem/energy_term.hpp>

namespace shapectl::test {

// Largest entry of |a − b| relative to the largest entry of |b| (with an absolute floor so
// that comparing zeros is reported instead of passing silently).
inline double relative_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const double scale = b.cwiseAbs().maxCoeff();
  return (a - b).cwiseAbs().maxCoeff() / std::max(scale, 1e-300);
}

inline Positions perturbed(const Positions& x, double amount, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amount, amount);
  Positions y = x;
  for (int i = 0; i < y.size(); ++i) y[i] += u(rng);
  return y;
}

inline Eigen::MatrixXd dense_hessian(const EnergyTerm& term, const Positions& x, bool project = false) {
  Triplets t;
  term.add_hessian(x, t, project);
  SparseMatrix H(x.size(), x.size());
  H.setFromTriplets(t.begin(), t.end());
  return Eigen::MatrixXd(H);
}

inline void expect_derivatives_match(const EnergyTerm& term, const Positions& x, double tolerance,
                                     double h = 1e-6) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  term.add_gradient(x, g);
  Eigen::VectorXd g_fd(x.size());
  Eigen::MatrixXd H_fd(x.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Positions xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    g_fd[i] = (term.value(xp) - term.value(xm)) / (2 * h);
    Eigen::VectorXd gp = Eigen::VectorXd::Zero(x.size()), gm = gp;
    term.add_gradient(xp, gp);
    term.add_gradient(xm, gm);
    H_fd.col(i) = (gp - gm) / (2 * h);
  }
  ASSERT_GT(g.cwiseAbs().maxCoeff(), 0) << term.name() << ": gradient is all zeros";
  EXPECT_LT(relative_error(g, g_fd), tolerance) << term.name() << " gradient";
  const Eigen::MatrixXd H = dense_hessian(term, x);
  if (H_fd.cwiseAbs().maxCoeff() > 0) {
    ASSERT_GT(H.cwiseAbs().maxCoeff(), 0) << term.name() << ": Hessian is all zeros";
    EXPECT_LT(relative_error(H, H_fd), tolerance) << term.name() << " Hessian";
  }
}

}  // namespace shapectl::test
