#include <shapectl/fem/neo_hookean.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tbb/task_arena.h>
#include <vector>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

const Material kFoam{.mu = 1e4, .kappa = 5e4, .density = 30};

Positions affine(const TetMesh& mesh, const Mat3& A, const Vec3& b) {
  Positions x(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i)
    x.segment<3>(3 * i) = A * mesh.rest_positions()[i] + b;
  return x;
}

TEST(NeoHookean, DerivativesMatchCentralDifferences) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const NeoHookean term(mesh, kFoam);
  std::mt19937 rng(42);
  for (int trial = 0; trial < 5; ++trial)
    test::expect_derivatives_match(term, test::perturbed(mesh.rest_vector(), 0.003, rng), 1e-6);
}

// Seeded materials, one per element, moduli spread over two decades (a two-material casting and
// more): a mix-up of elements and materials shows in the derivatives.
std::vector<Material> random_materials(const TetMesh& mesh, std::mt19937& rng) {
  std::uniform_real_distribution<double> log_modulus(3, 5);
  std::vector<Material> materials;
  for (std::size_t e = 0; e < mesh.tets().size(); ++e)
    materials.push_back({.mu = std::pow(10, log_modulus(rng)),
                         .kappa = std::pow(10, log_modulus(rng)),
                         .density = 30});
  return materials;
}

TEST(NeoHookean, PerElementMaterialsDerivativesMatchCentralDifferences) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  std::mt19937 rng(17);
  const NeoHookean term(mesh, random_materials(mesh, rng));
  for (int trial = 0; trial < 5; ++trial)
    test::expect_derivatives_match(term, test::perturbed(mesh.rest_vector(), 0.003, rng), 1e-6);
}

TEST(NeoHookean, PerElementMaterialsGiveEachElementItsOwnEnergyAndHessian) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  std::mt19937 rng(23);
  const std::vector<Material> materials = random_materials(mesh, rng);
  const NeoHookean term(mesh, materials);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.003, rng);
  double energy = 0;
  Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(x.size(), x.size());
  for (std::size_t e = 0; e < mesh.tets().size(); ++e) {
    const TetRest& t = mesh.tets()[e];
    Vec12 xe;
    for (int a = 0; a < 4; ++a) xe.segment<3>(3 * a) = x.segment<3>(3 * t.nodes[a]);
    Mat12 H;
    energy += neo_hookean_tet(t, materials[e], xe, nullptr, &H);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        hessian.block<3, 3>(3 * t.nodes[a], 3 * t.nodes[b]) += H.block<3, 3>(3 * a, 3 * b);
  }
  EXPECT_NEAR(term.value(x), energy, 1e-12 * std::abs(energy));
  EXPECT_TRUE(test::derivative_matches(test::dense_hessian(term, x), hessian, 1e-12,
                                       "per-element Hessian"));
}

TEST(NeoHookean, OneMaterialPerElementAllAlikeIsTheSingleMaterialBitForBit) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const NeoHookean single(mesh, kFoam);
  const NeoHookean each(mesh, std::vector<Material>(mesh.tets().size(), kFoam));
  std::mt19937 rng(29);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.003, rng);
  EXPECT_EQ(single.value(x), each.value(x));
  EXPECT_TRUE(
      (test::energy_gradient(single, x).array() == test::energy_gradient(each, x).array()).all());
  EXPECT_TRUE(
      (test::dense_hessian(single, x).array() == test::dense_hessian(each, x).array()).all());
  EXPECT_THROW(NeoHookean(mesh, std::vector<Material>(2, kFoam)), std::invalid_argument);
}

TEST(NeoHookean, RestStateHasZeroEnergyAndForce) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const NeoHookean term(mesh, kFoam);
  const Positions X = mesh.rest_vector();
  EXPECT_NEAR(term.value(X), 0.0, 1e-15);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(X.size());
  term.add_gradient(X, g);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-10);
}

TEST(NeoHookean, EnergyMatchesTheFormulaForAKnownDeformation) {
  const TetMesh mesh = make_box_mesh({1, 1, 1}, {1, 1, 1});
  const NeoHookean term(mesh, kFoam);
  Mat3 A;
  A << 1.2, 0.1, 0, 0, 0.9, 0.05, 0.02, 0, 1.1;
  const double J = A.determinant();
  const double psi = 0.5 * kFoam.mu * (A.squaredNorm() - 3) - kFoam.mu * std::log(J) +
                     0.5 * kFoam.kappa * std::log(J) * std::log(J);
  EXPECT_NEAR(term.value(affine(mesh, A, Vec3(0.3, -1, 2))), psi * 1.0, 1e-9 * std::abs(psi));
}

TEST(NeoHookean, PatchTestAffineDeformationLeavesInteriorNodesForceFree) {
  const TetMesh mesh = make_box_mesh({0.3, 0.3, 0.3}, {3, 3, 3});
  const NeoHookean term(mesh, kFoam);
  Mat3 A;
  A << 1.1, 0.2, -0.05, 0.03, 0.95, 0.1, -0.1, 0.02, 1.05;
  const Positions x = affine(mesh, A, Vec3(0.01, 0.02, -0.03));
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  term.add_gradient(x, g);
  // Uniform F in every element.
  for (const auto& t : mesh.tets()) {
    Mat3 Ds;
    for (int c = 0; c < 3; ++c)
      Ds.col(c) = x.segment<3>(3 * t.nodes[c + 1]) - x.segment<3>(3 * t.nodes[0]);
    EXPECT_LT((Ds * t.Dm_inverse - A).norm(), 1e-12);
  }
  const Vec3 lo = mesh.bounds_min(), hi = mesh.bounds_max();
  int interior = 0;
  double boundary_force = 0;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Vec3& X = mesh.rest_positions()[i];
    const bool inside = ((X - lo).minCoeff() > 1e-9) && ((hi - X).minCoeff() > 1e-9);
    if (inside) {
      ++interior;
      EXPECT_LT(g.segment<3>(3 * i).norm(), 1e-9) << "interior node " << i;
    } else {
      boundary_force = std::max(boundary_force, g.segment<3>(3 * i).norm());
    }
  }
  EXPECT_EQ(interior, 8);
  EXPECT_GT(boundary_force, 1.0);  // the deformation is not trivially force-free
}

TEST(NeoHookean, EnergyIsInvariantUnderRotation) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const NeoHookean term(mesh, kFoam);
  std::mt19937 rng(7);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.003, rng);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Positions y = x;
  for (int i = 0; i < mesh.node_count(); ++i)
    y.segment<3>(3 * i) = R * x.segment<3>(3 * i) + Vec3(1, 2, 3);
  const double e = term.value(x);
  EXPECT_GT(e, 0);
  EXPECT_NEAR(term.value(y), e, 1e-10 * e);
}

TEST(NeoHookean, InvertedElementHasInfiniteEnergy) {
  const TetMesh mesh = make_box_mesh({1, 1, 1}, {1, 1, 1});
  const NeoHookean term(mesh, kFoam);
  Mat3 mirror = Mat3::Identity();
  mirror(2, 2) = -1;
  EXPECT_TRUE(std::isinf(term.value(affine(mesh, mirror, Vec3::Zero()))));
  EXPECT_TRUE(std::isinf(term.value(affine(mesh, Mat3::Zero(), Vec3::Zero()))));
}

TEST(NeoHookean, InvertedElementMakesTheFusedGradientNaNLikeTheSeparateOne) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {4, 1, 1});
  const NeoHookean term(mesh, kFoam);
  Positions x = mesh.rest_vector();
  const int node = mesh.tets()[0].nodes[0];
  // Push one corner through the opposite face.
  x.segment<3>(3 * node) =
      3 * x.segment<3>(3 * mesh.tets()[0].nodes[1]) - 2 * x.segment<3>(3 * node);
  Eigen::VectorXd separate = Eigen::VectorXd::Zero(x.size()), fused = separate;
  term.add_gradient(x, separate);
  EXPECT_TRUE(std::isinf(term.value_and_add_gradient(x, fused)));
  EXPECT_TRUE(std::isnan(fused[3 * node]));
  EXPECT_TRUE((fused.array().isNaN() == separate.array().isNaN()).all());
  EXPECT_TRUE(fused.array().isNaN().any() && !fused.array().isNaN().all());
}

TEST(NeoHookean, EnergyAndGradientAreTheSameBitsOnOneThreadAndOnMany) {
  // Enough tets and nodes for many parallel chunks; a perturbed state so every entry is nonzero.
  const TetMesh mesh = make_box_mesh({0.32, 0.08, 0.08}, {16, 4, 4});
  const NeoHookean term(mesh, kFoam);
  std::mt19937 rng(11);
  const Positions x = test::perturbed(mesh.rest_vector(), 0.002, rng);
  struct Result {
    double energy = 0, fused_energy = 0;
    Eigen::VectorXd gradient, fused_gradient;
  };
  const auto evaluate = [&](int threads) {
    Result r;
    r.gradient = r.fused_gradient = Eigen::VectorXd::Zero(x.size());
    tbb::task_arena(threads).execute([&] {
      r.energy = term.value(x);
      term.add_gradient(x, r.gradient);
      r.fused_energy = term.value_and_add_gradient(x, r.fused_gradient);
    });
    return r;
  };
  const Result one = evaluate(1);
  ASSERT_GT(one.energy, 0);
  ASSERT_GT(one.gradient.cwiseAbs().minCoeff(), 0);
  EXPECT_EQ(one.fused_energy, one.energy);
  EXPECT_TRUE((one.fused_gradient.array() == one.gradient.array()).all());
  for (const int threads : {2, 4}) {
    for (int run = 0; run < 3; ++run) {
      const Result many = evaluate(threads);
      EXPECT_EQ(many.energy, one.energy) << threads << " threads";
      EXPECT_EQ(many.fused_energy, one.energy) << threads << " threads";
      EXPECT_TRUE((many.gradient.array() == one.gradient.array()).all()) << threads << " threads";
      EXPECT_TRUE((many.fused_gradient.array() == one.gradient.array()).all())
          << threads << " threads";
    }
  }
}

TEST(NeoHookean, ProjectedHessianIsPositiveSemidefiniteAndTrueOneIsNot) {
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {2, 1, 1});
  const NeoHookean term(mesh, kFoam);
  // Strong compression along x makes the true Hessian indefinite.
  Mat3 A = Mat3::Identity();
  A(0, 0) = 0.3;
  const Positions x = affine(mesh, A, Vec3::Zero());
  const Eigen::MatrixXd H = test::dense_hessian(term, x, false);
  const Eigen::MatrixXd P = test::dense_hessian(term, x, true);
  const double scale = H.cwiseAbs().maxCoeff();
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff(),
            -1e-6 * scale);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff(),
            -1e-9 * scale);
}

TEST(NeoHookean, TrueHessianEqualsTheProjectedOneWhereNothingIsClamped) {
  // The true Hessian is assembled in closed form per node pair, the projected one as V Bᵀ C B
  // from the 9 × 9 ∂P/∂F. A turned, dilated object (J > 1) has C positive definite: nothing is
  // clamped, and the two must agree to round-off. (At rest the rotations are C's null space,
  // and any strain that shrinks makes them negative.)
  const TetMesh mesh = make_box_mesh({0.1, 0.02, 0.02}, {3, 1, 1});
  const NeoHookean term(mesh, kFoam);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Quaterniond turn = Eigen::Quaterniond::UnitRandom();
    const double dilation = 1.02 + 0.02 * trial;
    const Positions x = affine(mesh, dilation * turn.toRotationMatrix(),
                               Vec3(uniform(rng), uniform(rng), uniform(rng)));
    const Eigen::MatrixXd H = test::dense_hessian(term, x, false);
    const Eigen::MatrixXd P = test::dense_hessian(term, x, true);
    EXPECT_LT((H - P).cwiseAbs().maxCoeff(), 1e-10 * H.cwiseAbs().maxCoeff()) << "trial " << trial;
  }
}

TEST(NeoHookean, SmallStrainMatchesLinearElasticity) {
  // Uniaxial stress is awkward to impose; a uniform dilation ε gives energy
  // density 9/2 K ε² with bulk modulus K = λ + 2μ/3 (here κ plays λ).
  const TetMesh mesh = make_box_mesh({1, 1, 1}, {1, 1, 1});
  const Material m = material_from_youngs(1e5, 0.3, 0);
  const NeoHookean term(mesh, m);
  const double eps = 1e-5;
  const double K = m.kappa + 2 * m.mu / 3;
  const double expected = 4.5 * K * eps * eps;
  EXPECT_NEAR(term.value(affine(mesh, (1 + eps) * Mat3::Identity(), Vec3::Zero())), expected,
              1e-3 * expected);
}

}  // namespace
}  // namespace shapectl
