#include <shapectl/robot/joint_limits.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

JointLimits test_limits() {
  // Third joint continuous: no barrier.
  return JointLimits(Eigen::Vector3d(-1, 0, -kInf), Eigen::Vector3d(1, 0.5, kInf), 0.1, 10.0);
}

TEST(CubicBarrier, IsTwiceContinuousAtZeroAndSquaresFromItsResidual) {
  const CubicBarrier barrier{4.0};
  EXPECT_EQ(barrier.value(-0.3), 0.0);
  EXPECT_EQ(barrier.value(0.0), 0.0);
  EXPECT_EQ(barrier.derivative(0.0), 0.0);
  EXPECT_DOUBLE_EQ(barrier.value(0.5), 0.5);
  EXPECT_DOUBLE_EQ(barrier.derivative(0.5), 3.0);
  EXPECT_DOUBLE_EQ(0.5 * std::pow(barrier.residual(0.5), 2), barrier.value(0.5));
  const auto residual = [&](const Eigen::VectorXd& v) { return barrier.residual(v[0]); };
  EXPECT_TRUE(test::derivative_matches(
      Eigen::VectorXd::Constant(1, barrier.residual_derivative(0.5)),
      test::central_difference_gradient(residual, Eigen::VectorXd::Constant(1, 0.5), 1e-6), 1e-8,
      "cubic barrier residual derivative"));
}

TEST(JointLimits, ZeroInsideTheMarginAndGrowingOutside) {
  const JointLimits limits = test_limits();
  EXPECT_EQ(limits.value(Eigen::Vector3d(0.85, 0.25, 1e6)), 0.0);
  EXPECT_NEAR(limits.value(Eigen::Vector3d(0.95, 0.25, 0)), 10 * std::pow(0.05, 3), 1e-15);
  EXPECT_NEAR(limits.value(Eigen::Vector3d(-1.2, 0.25, 0)), 10 * std::pow(0.3, 3), 1e-14);
  // A range narrower than four margins (a 10 cm joint under a 0.1 margin) keeps a quarter of
  // its range from each limit, not the margin: its middle half is free, not pinned.
  const JointLimits narrow(Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, 0.1),
                           0.1, 10.0);
  EXPECT_EQ(narrow.value(Eigen::VectorXd::Constant(1, 0.03)), 0.0);
  EXPECT_EQ(narrow.value(Eigen::VectorXd::Constant(1, 0.07)), 0.0);
  EXPECT_NEAR(narrow.value(Eigen::VectorXd::Constant(1, 0.0)), 10 * std::pow(0.025, 3), 1e-15);
  EXPECT_DOUBLE_EQ(joint_margin(0, 0.025, 0.05), 0.025 / 4);  // a YuMi finger
  EXPECT_DOUBLE_EQ(joint_margin(-2, 2, 0.05), 0.05);
  EXPECT_DOUBLE_EQ(joint_margin(-INFINITY, INFINITY, 0.05), 0.05);
}

TEST(JointLimits, GradientAndResidualJacobianMatchCentralDifferences) {
  const JointLimits limits = test_limits();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-1.5, 1.5);
  const auto barrier = [&](const Eigen::VectorXd& t) { return limits.value(t); };
  const auto residuals = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    Eigen::VectorXd r;
    limits.residuals(t, r);
    return r;
  };
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d theta(angle(rng), angle(rng) * 0.5, angle(rng));
    Eigen::VectorXd gradient, r;
    Eigen::MatrixXd jacobian;
    const double value = limits.value(theta, &gradient);
    limits.residuals(theta, r, &jacobian);
    EXPECT_NEAR(0.5 * r.squaredNorm(), value, 1e-12 * std::max(value, 1.0));
    const Eigen::VectorXd numeric_gradient =
        test::central_difference_gradient(barrier, theta, 1e-6);
    const Eigen::MatrixXd numeric_jacobian =
        test::central_difference_jacobian(residuals, theta, 1e-6);
    if (value > 0) {  // some joint inside its margin
      EXPECT_TRUE(
          test::derivative_matches(gradient, numeric_gradient, 1e-6, "joint-limit gradient"));
      EXPECT_TRUE(test::derivative_matches(jacobian, numeric_jacobian, 1e-6,
                                           "joint-limit residual Jacobian"));
      ++compared;
    } else {  // every joint clear of its margins: no barrier, no derivatives
      EXPECT_EQ(gradient.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_EQ(numeric_gradient.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_EQ(jacobian.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_EQ(numeric_jacobian.cwiseAbs().maxCoeff(), 0.0);
    }
  }
  EXPECT_GE(compared, 10);  // most trials leave some range
}

TEST(JointLimits, ViolationsListJointsOutsideTheirHardLimits) {
  const RobotModel model = RobotModel::from_urdf_string(R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
    <joint name="j2" type="continuous"><parent link="b"/><child link="c"/></joint>
  </robot>)",
                                                        "r.urdf");
  const auto violations = limit_violations(model, Eigen::Vector2d(1.5, 100));
  ASSERT_EQ(violations.size(), 1u);
  EXPECT_EQ(violations[0].joint, "j1");
  EXPECT_EQ(violations[0].value, 1.5);
  EXPECT_TRUE(limit_violations(model, Eigen::Vector2d(0.5, -100)).empty());
}

}  // namespace
}  // namespace shapectl
