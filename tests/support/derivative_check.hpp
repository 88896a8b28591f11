#pragma once
// The tests' one derivative checker: central-difference Jacobians, and a comparison that fails
// when it would compare only (near) zeros, so that no derivative check passes vacuously.
// Energies, Jacobians, sensitivities and barrier gradients all go through it.
#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <string_view>

#include <shapectl/fem/energy_term.hpp>

namespace shapectl::test {

// A vector-valued function of a vector. Give lambdas an explicit `-> Eigen::VectorXd`: one that
// returns an Eigen expression of its locals would leave it dangling.
using VectorFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
using ScalarFunction = std::function<double(const Eigen::VectorXd&)>;

// Column j is (f(x + h e_j) − f(x − h e_j)) / 2h: rows are f's entries, columns x's.
inline Eigen::MatrixXd central_difference_jacobian(const VectorFunction& f,
                                                   const Eigen::VectorXd& x, double h) {
  Eigen::MatrixXd jacobian;
  for (int j = 0; j < x.size(); ++j) {
    Eigen::VectorXd plus = x, minus = x;
    plus[j] += h;
    minus[j] -= h;
    const Eigen::VectorXd column = (f(plus) - f(minus)) / (2 * h);
    if (j == 0) jacobian.resize(column.size(), x.size());
    jacobian.col(j) = column;
  }
  return jacobian;
}

// The gradient of a scalar f, as a column: the transpose of its one-row Jacobian.
inline Eigen::VectorXd central_difference_gradient(const ScalarFunction& f,
                                                   const Eigen::VectorXd& x, double h) {
  const auto one_row = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, f(y));
  };
  return central_difference_jacobian(one_row, x, h).transpose();
}

// Below this largest |entry| a reference derivative counts as zero. Central differences with
// h = 1e-6 carry round-off near 1e-10·|f|; the derivatives checked here are far above.
constexpr double kDerivativeFloor = 1e-8;

// Passes when max|analytic − reference| ≤ tolerance · max|reference| (the relative error of
// the largest entries) and max|reference| ≥ floor: comparing (near) zeros fails. The reference
// is what is trusted, usually central differences. `what` names the derivative in messages.
inline ::testing::AssertionResult derivative_matches(const Eigen::MatrixXd& analytic,
                                                     const Eigen::MatrixXd& reference,
                                                     double tolerance, std::string_view what,
                                                     double floor = kDerivativeFloor) {
  if (analytic.rows() != reference.rows() || analytic.cols() != reference.cols() ||
      reference.size() == 0)
    return ::testing::AssertionFailure()
           << what << ": analytic is " << analytic.rows() << "x" << analytic.cols()
           << ", reference " << reference.rows() << "x" << reference.cols();
  // maxCoeff skips NaN: say so before it could hide one.
  if (!analytic.allFinite() || !reference.allFinite())
    return ::testing::AssertionFailure()
           << what << ": the " << (analytic.allFinite() ? "reference" : "analytic")
           << " has an entry that is not finite";
  const double scale = reference.cwiseAbs().maxCoeff();
  if (!(scale >= floor))
    return ::testing::AssertionFailure()
           << what << ": nothing to compare, the reference is (near) zero: max |entry| " << scale
           << " < floor " << floor << " (analytic: max |entry| " << analytic.cwiseAbs().maxCoeff()
           << ")";
  Eigen::Index row = 0, col = 0;
  const double error = (analytic - reference).cwiseAbs().maxCoeff(&row, &col) / scale;
  std::ostringstream worst;
  worst << "relative error " << error << " (tolerance " << tolerance << "), worst entry (" << row
        << ", " << col << "): analytic " << analytic(row, col) << ", reference "
        << reference(row, col) << ", max |reference| " << scale;
  if (!(error <= tolerance)) return ::testing::AssertionFailure() << what << ": " << worst.str();
  return ::testing::AssertionSuccess() << what << ": " << worst.str();
}

inline Positions perturbed(const Positions& x, double amount, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amount, amount);
  Positions y = x;
  for (int i = 0; i < y.size(); ++i) y[i] += u(rng);
  return y;
}

inline Eigen::VectorXd energy_gradient(const EnergyTerm& term, const Positions& x) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  term.add_gradient(x, g);
  return g;
}

inline Eigen::MatrixXd dense_hessian(const EnergyTerm& term, const Positions& x,
                                     bool project = false) {
  const Triplets t = term.hessian_triplets(x, project);
  SparseMatrix H(x.size(), x.size());
  H.setFromTriplets(t.begin(), t.end());
  return Eigen::MatrixXd(H);
}

// An energy term's gradient against central differences of its value.
inline void expect_gradient_matches(const EnergyTerm& term, const Positions& x, double tolerance,
                                    double h = 1e-6) {
  const auto value = [&](const Eigen::VectorXd& y) { return term.value(y); };
  EXPECT_TRUE(derivative_matches(energy_gradient(term, x), central_difference_gradient(value, x, h),
                                 tolerance, std::string(term.name()) + " gradient"));
}

// An energy term's Hessian against central differences of its gradient.
inline void expect_hessian_matches(const EnergyTerm& term, const Positions& x, double tolerance,
                                   double h = 1e-6) {
  const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return energy_gradient(term, y);
  };
  EXPECT_TRUE(derivative_matches(dense_hessian(term, x),
                                 central_difference_jacobian(gradient, x, h), tolerance,
                                 std::string(term.name()) + " Hessian"));
}

// The fused value_and_add_gradient against value and add_gradient: the same energy and the same
// gradient bit for bit, added onto what `gradient` held (a seeded random start). With
// add_gradient checked against central differences, so is the fused gradient.
inline void expect_fused_matches_separate(const EnergyTerm& term, const Positions& x) {
  std::mt19937 rng(7);
  const Eigen::VectorXd start = perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
  Eigen::VectorXd separate = start, fused = start;
  term.add_gradient(x, separate);
  const double energy = term.value_and_add_gradient(x, fused);
  EXPECT_EQ(energy, term.value(x)) << term.name() << " fused energy differs from value";
  EXPECT_TRUE((fused.array() == separate.array()).all())
      << term.name() << " fused gradient differs from add_gradient by up to "
      << (fused - separate).cwiseAbs().maxCoeff();
}

inline void expect_derivatives_match(const EnergyTerm& term, const Positions& x, double tolerance,
                                     double h = 1e-6) {
  expect_gradient_matches(term, x, tolerance, h);
  expect_fused_matches_separate(term, x);
  expect_hessian_matches(term, x, tolerance, h);
}

}  // namespace shapectl::test
