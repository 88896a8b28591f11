#include <shapectl/fem/gravity.hpp>

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include <shapectl/fem/material.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

TEST(Gravity, LumpedMassesSumToTheTotalMass) {
  const TetMesh mesh = make_box_mesh({0.32, 0.03, 0.03}, {16, 4, 4});
  const Eigen::VectorXd m = lumped_masses(mesh, 40.0);
  EXPECT_NEAR(m.sum(), 40.0 * 0.32 * 0.03 * 0.03, 1e-12);
  EXPECT_GT(m.minCoeff(), 0);
}

TEST(Gravity, PerElementDensitiesGiveEachElementItsMass) {
  const TetMesh mesh = make_box_mesh({0.32, 0.03, 0.03}, {16, 4, 4});
  std::vector<Material> materials;
  double mass = 0;
  for (const TetRest& t : mesh.tets()) {
    materials.push_back({.density = t.nodes[0] % 2 ? 40.0 : 400.0});
    mass += materials.back().density * t.volume;
  }
  const Eigen::VectorXd m = lumped_masses(mesh, materials);
  EXPECT_NEAR(m.sum(), mass, 1e-12 * mass);
  // One material for all is the scalar density's lumping, bit for bit.
  EXPECT_TRUE(
      (lumped_masses(mesh, {Material{.density = 40}}).array() == lumped_masses(mesh, 40.0).array())
          .all());
  EXPECT_NEAR(Gravity(mesh, materials, Vec3(0, 0, -9.81)).weight(), mass * 9.81, 1e-12);
  EXPECT_THROW(lumped_masses(mesh, std::vector<Material>(2)), std::invalid_argument);
}

TEST(Gravity, EnergyIsMassTimesGTimesHeight) {
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.1}, {2, 2, 2});
  const Gravity term(mesh, 100.0, Vec3(0, 0, -9.81));
  const double mass = 100.0 * 1e-3;
  Positions x = mesh.rest_vector();
  for (int i = 0; i < mesh.node_count(); ++i) x[3 * i + 2] += 0.5;  // lift by 0.5 m
  EXPECT_NEAR(term.value(x) - term.value(mesh.rest_vector()), mass * 9.81 * 0.5, 1e-12);
  EXPECT_NEAR(term.weight(), mass * 9.81, 1e-12);
}

TEST(Gravity, DerivativesMatchCentralDifferences) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const Gravity term(mesh, 30.0, Vec3(0.1, -0.2, -9.81));
  std::mt19937 rng(3);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.003, rng);
  test::expect_gradient_matches(term, x, 1e-6);
  // Gravity is linear in x: its Hessian is zero, and so are differences of its gradient.
  const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return test::energy_gradient(term, y);
  };
  EXPECT_EQ(test::dense_hessian(term, x).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(test::central_difference_jacobian(gradient, x, 1e-6).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Material, YoungsModulusConversion) {
  const Material m = material_from_youngs(2.6e5, 0.3, 40);
  EXPECT_NEAR(m.mu, 1e5, 1e-6);
  EXPECT_NEAR(m.kappa, 2.6e5 * 0.3 / (1.3 * 0.4), 1e-6);
  EXPECT_EQ(m.density, 40);
}

}  // namespace
}  // namespace shapectl
