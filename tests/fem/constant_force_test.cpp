#include <shapectl/fem/constant_force.hpp>

#include <gtest/gtest.h>

#include <random>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

// Seeded forces of up to `amount` newtons per component, on every node.
Eigen::VectorXd random_forces(int node_count, double amount, std::mt19937& rng) {
  return test::perturbed(Eigen::VectorXd::Zero(3 * node_count), amount, rng);
}

TEST(ConstantForce, EnergyIsMinusTheForcesDotThePositions) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  std::mt19937 rng(11);
  const Eigen::VectorXd f = random_forces(mesh.node_count(), 2.0, rng);
  const ConstantForce term("loads", f);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.01, rng);
  EXPECT_EQ(term.name(), "loads");
  EXPECT_NEAR(term.value(x), -f.dot(x), 1e-12 * f.cwiseAbs().sum());
  // Moving every node by d costs −(Σ f)·d: work done against the loads.
  const Vec3 d(0.01, -0.02, 0.03);
  Positions moved = x;
  Vec3 total = Vec3::Zero();
  for (int i = 0; i < mesh.node_count(); ++i) {
    moved.segment<3>(3 * i) += d;
    total += f.segment<3>(3 * i);
  }
  EXPECT_NEAR(term.value(moved) - term.value(x), -total.dot(d), 1e-12);
  EXPECT_TRUE(term.forces().isApprox(f));
}

TEST(ConstantForce, DerivativesMatchCentralDifferences) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  std::mt19937 rng(5);
  const ConstantForce term("loads", random_forces(mesh.node_count(), 0.5, rng));
  for (int trial = 0; trial < 3; ++trial) {
    const Positions x = test::perturbed(mesh.rest_vector(), 0.003, rng);
    test::expect_gradient_matches(term, x, 1e-6);
    test::expect_fused_matches_separate(term, x);
    // Linear in x: its Hessian is zero, and so are differences of its gradient.
    const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
      return test::energy_gradient(term, y);
    };
    EXPECT_EQ(test::dense_hessian(term, x).size(), x.size() * x.size());
    EXPECT_EQ(test::dense_hessian(term, x).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(test::central_difference_jacobian(gradient, x, 1e-6).cwiseAbs().maxCoeff(), 0.0);
  }
}

}  // namespace
}  // namespace shapectl
