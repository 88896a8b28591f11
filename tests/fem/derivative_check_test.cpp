// The tests' derivative checker itself (tests/support/derivative_check.hpp): it passes a right
// derivative and fails a wrong one, a comparison of zeros and a mismatch in size, so that every
// check built on it means something.
#include "support/derivative_check.hpp"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace shapectl {
namespace {

// f(x) = (x0 x1, sin x2): two rows, three columns, a Jacobian known in closed form.
Eigen::VectorXd two_of_three(const Eigen::VectorXd& x) {
  return Eigen::Vector2d(x[0] * x[1], std::sin(x[2]));
}

Eigen::MatrixXd two_of_three_jacobian(const Eigen::VectorXd& x) {
  Eigen::MatrixXd J(2, 3);
  J << x[1], x[0], 0, 0, 0, std::cos(x[2]);
  return J;
}

Eigen::VectorXd check_point() { return Eigen::Vector3d(0.3, -1.2, 0.7); }

Eigen::MatrixXd numeric_jacobian() {
  return test::central_difference_jacobian(two_of_three, check_point(), 1e-6);
}

// The Jacobian with one entry wrong by a sign.
Eigen::MatrixXd wrong_jacobian() {
  Eigen::MatrixXd J = two_of_three_jacobian(check_point());
  J(1, 2) = -J(1, 2);
  return J;
}

TEST(DerivativeCheck, CentralDifferencesGiveAKnownJacobianRowsByColumns) {
  const Eigen::MatrixXd numeric = numeric_jacobian();
  ASSERT_EQ(numeric.rows(), 2);
  ASSERT_EQ(numeric.cols(), 3);
  EXPECT_LT((numeric - two_of_three_jacobian(check_point())).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(test::derivative_matches(two_of_three_jacobian(check_point()), numeric, 1e-8, "f"));
}

TEST(DerivativeCheck, CentralDifferencesGiveAScalarFunctionsGradientAsAColumn) {
  // g(x) = x0² x1 + exp(x2): gradient (2 x0 x1, x0², exp(x2)).
  const auto g = [](const Eigen::VectorXd& x) { return x[0] * x[0] * x[1] + std::exp(x[2]); };
  const Eigen::VectorXd x = check_point();
  const Eigen::VectorXd numeric = test::central_difference_gradient(g, x, 1e-6);
  ASSERT_EQ(numeric.size(), 3);
  EXPECT_TRUE(
      test::derivative_matches(Eigen::Vector3d(2 * x[0] * x[1], x[0] * x[0], std::exp(x[2])),
                               numeric, 1e-8, "g"));
}

TEST(DerivativeCheck, AWrongDerivativeFailsNamingItsWorstEntry) {
  EXPECT_NONFATAL_FAILURE(EXPECT_TRUE(test::derivative_matches(wrong_jacobian(), numeric_jacobian(),
                                                               1e-6, "f")),
                          "f: relative error");
  const std::string message =
      test::derivative_matches(wrong_jacobian(), numeric_jacobian(), 1e-6, "f").message();
  EXPECT_NE(message.find("worst entry (1, 2)"), std::string::npos) << message;
  // An error just above the tolerance fails too; just below passes.
  const Eigen::MatrixXd reference = Eigen::MatrixXd::Constant(2, 2, 1.0);
  EXPECT_FALSE(test::derivative_matches(reference * (1 + 2e-6), reference, 1e-6, "f"));
  EXPECT_TRUE(test::derivative_matches(reference * (1 + 0.5e-6), reference, 1e-6, "f"));
}

TEST(DerivativeCheck, BothSidesZeroFailsRatherThanPassingVacuously) {
  EXPECT_NONFATAL_FAILURE(EXPECT_TRUE(test::derivative_matches(Eigen::MatrixXd::Zero(2, 3),
                                                               Eigen::MatrixXd::Zero(2, 3), 1e-6,
                                                               "zeros")),
                          "zeros: nothing to compare, the reference is (near) zero");
  // Equal but tiny is as good as zero: below the default floor, and below a floor given.
  const Eigen::MatrixXd tiny = Eigen::MatrixXd::Constant(2, 3, 1e-12);
  EXPECT_FALSE(test::derivative_matches(tiny, tiny, 1e-6, "tiny"));
  const Eigen::MatrixXd small = Eigen::MatrixXd::Constant(2, 3, 1e-4);
  EXPECT_TRUE(test::derivative_matches(small, small, 1e-6, "small"));
  EXPECT_FALSE(test::derivative_matches(small, small, 1e-6, "small", 1e-3));
}

// Ones with a NaN that maxCoeff alone would skip.
Eigen::MatrixXd not_a_number() {
  Eigen::MatrixXd m = Eigen::MatrixXd::Ones(2, 3);
  m(0, 1) = std::numeric_limits<double>::quiet_NaN();
  return m;
}

TEST(DerivativeCheck, MismatchedSizesAndNotANumberFail) {
  EXPECT_NONFATAL_FAILURE(EXPECT_TRUE(test::derivative_matches(Eigen::MatrixXd::Ones(3, 2),
                                                               Eigen::MatrixXd::Ones(2, 3), 1e-6,
                                                               "f")),
                          "f: analytic is 3x2, reference 2x3");
  EXPECT_NONFATAL_FAILURE(
      EXPECT_TRUE(test::derivative_matches(not_a_number(), Eigen::MatrixXd::Ones(2, 3), 1e-6, "f")),
      "f: the analytic has an entry that is not finite");
  EXPECT_FALSE(test::derivative_matches(Eigen::MatrixXd::Ones(2, 3), not_a_number(), 1e-6, "f"));
}

// E(x) = Σ xᵢ² + xᵢ³: gradient 2xᵢ + 3xᵢ², Hessian diagonal 2 + 6xᵢ. A fault breaks one of them,
// or makes the fused value and gradient differ from the separate ones.
enum class Fault { None, Gradient, Hessian, FusedValue, FusedGradient };

class CubicTerm final : public EnergyTerm {
 public:
  explicit CubicTerm(Fault fault) : fault_(fault) {}
  std::string_view name() const override { return "cubic"; }
  double value(const Positions& x) const override {
    return (x.array().square() + x.array().cube()).sum();
  }
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override {
    gradient.array() += 2 * x.array() + 3 * x.array().square();
    if (fault_ == Fault::Gradient) gradient[1] += 0.1;  // a constant: differences of it stay right
  }
  double value_and_add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override {
    const double e = EnergyTerm::value_and_add_gradient(x, gradient);
    if (fault_ == Fault::FusedGradient) gradient[4] *= 1 + 1e-15;  // one rounding apart
    return fault_ == Fault::FusedValue ? e * (1 + 1e-15) : e;
  }
  // One element per node of energy_point()'s two: a diagonal 3×3 block.
  void hessian_elements(const Positions&, ElementNodes& elements) const override {
    elements.add({0});
    elements.add({1});
  }
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool) const override {
    sink.add_blocks([&](std::size_t node, double* block) {
      Eigen::Map<Mat3> H(block);
      H.setZero();
      for (int d = 0; d < 3; ++d) {
        const int i = 3 * static_cast<int>(node) + d;
        H(d, d) = 2 + 6 * x[i] + (fault_ == Fault::Hessian && i == 2 ? 0.1 : 0.0);
      }
    });
  }

 private:
  Fault fault_;
};

// E(x) = Σ (i + 1) xᵢ: a gradient, but a Hessian of zeros (as gravity's).
class LinearTerm final : public EnergyTerm {
 public:
  std::string_view name() const override { return "linear"; }
  double value(const Positions& x) const override {
    return x.dot(Eigen::VectorXd::LinSpaced(x.size(), 1, static_cast<double>(x.size())));
  }
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override {
    gradient += Eigen::VectorXd::LinSpaced(x.size(), 1, static_cast<double>(x.size()));
  }
  void hessian_elements(const Positions&, ElementNodes&) const override {}
  void add_hessian(const Positions&, ElementHessianSink&, bool) const override {}
};

Positions energy_point() {
  Positions x(6);
  x << 0.1, -0.2, 0.3, 0.05, -0.4, 0.25;
  return x;
}

TEST(DerivativeCheck, EnergyTermCheckPassesRightDerivativesAndFailsEachWrongOne) {
  test::expect_derivatives_match(CubicTerm(Fault::None), energy_point(), 1e-6);
  // Exactly one failure each: the other derivative is still right.
  EXPECT_NONFATAL_FAILURE(test::expect_derivatives_match(CubicTerm(Fault::Gradient), energy_point(),
                                                         1e-6),
                          "cubic gradient: relative error");
  EXPECT_NONFATAL_FAILURE(test::expect_derivatives_match(CubicTerm(Fault::Hessian), energy_point(),
                                                         1e-6),
                          "cubic Hessian: relative error");
  EXPECT_NONFATAL_FAILURE(test::expect_derivatives_match(CubicTerm(Fault::FusedValue),
                                                         energy_point(), 1e-6),
                          "cubic fused energy differs");
  EXPECT_NONFATAL_FAILURE(test::expect_derivatives_match(CubicTerm(Fault::FusedGradient),
                                                         energy_point(), 1e-6),
                          "cubic fused gradient differs");
}

TEST(DerivativeCheck, EnergyTermWithAZeroHessianFailsTheHessianCheck) {
  test::expect_gradient_matches(LinearTerm(), energy_point(), 1e-6);
  EXPECT_NONFATAL_FAILURE(test::expect_derivatives_match(LinearTerm(), energy_point(), 1e-6),
                          "linear Hessian: nothing to compare");
}

}  // namespace
}  // namespace shapectl
