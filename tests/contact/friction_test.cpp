// Lagged Coulomb friction on the obstacle contacts (issue 34): derivatives against central
// differences in both branches of the mollifier, PSD blocks, the Coulomb force of a slide, and
// the lag's derivatives (λ, n, w of the pairs; the force's lag Jacobian) likewise.
#include <shapectl/contact/friction.hpp>

#include <gtest/gtest.h>

#include <shapectl/contact/friction_lag.hpp>

#include <Eigen/Eigenvalues>
#include <iostream>
#include <random>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

constexpr double kDhat = 0.01;

// A 0.1 × 0.1 × 0.02 box centred at the origin on a table, a ball on its top face (obstacle
// point – object triangle) and a bar across its −y face (obstacle segment – object edge), each
// about 0.4 d̂ away: pairs with one, two and three object nodes.
std::vector<Obstacle> obstacles() {
  const double gap = 0.4 * kDhat;
  return {make_plane("table", Vec3(0, 0, -0.01 - gap), Vec3(0, 0, 1)),
          make_sphere("ball", Vec3(0.013, 0.011, 0.01 + gap + 0.02), 0.02),
          make_capsule("bar", Vec3(-0.04, -0.05 - gap - 0.003, 0.004),
                       Vec3(0.04, -0.05 - gap - 0.003, -0.002), 0.003)};
}

struct Scenario {
  TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {4, 4, 1});
  ObstacleContact contact{mesh, obstacles(), kDhat, 3.0};
};

// Friction lagged at a perturbed rest shape (also the anchor) with slip length ε, and a state
// that moved every node by `shift` plus a random `amount` from it.
struct Lagged {
  Positions anchor;
  Positions x;
};
Lagged lagged_state(const Scenario& s, const Vec3& shift, double amount, std::mt19937& rng) {
  Lagged l;
  l.anchor = test::perturbed(s.mesh.rest_vector(), 0.05 * kDhat, rng);
  l.x = test::perturbed(l.anchor, amount, rng);
  for (int i = 0; i < s.mesh.node_count(); ++i) l.x.segment<3>(3 * i) += shift;
  return l;
}

void expect_every_pair_kind(const std::vector<ContactPair>& pairs) {
  std::array<int, 4> by_size{};
  for (const ContactPair& p : pairs) {
    ++by_size[p.node_count];
    EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
    double sum = 0;
    for (int a = 0; a < p.node_count; ++a) {
      EXPECT_GE(p.weights[a], -1e-12);
      sum += p.weights[a];
    }
    EXPECT_NEAR(sum, 1, 1e-12);
    EXPECT_GT(p.force, 0);
  }
  for (int k = 1; k <= 3; ++k) EXPECT_GT(by_size[k], 0) << "no pair of " << k << " object nodes";
}

TEST(Friction, MollifierIsC1AndMeetsTheKinkAtTheSlipLength) {
  const double eps = 1e-3;
  EXPECT_DOUBLE_EQ(friction_mollifier(0, eps), eps / 3);
  EXPECT_DOUBLE_EQ(friction_mollifier(eps, eps), eps);
  EXPECT_DOUBLE_EQ(friction_mollifier(2 * eps, eps), 2 * eps);
  // f₁ = y · (f₁/y): 0 at 0, 1 at ε from both sides.
  EXPECT_NEAR(eps * friction_mollifier_slope_over_y(eps * (1 - 1e-12), eps), 1, 1e-9);
  EXPECT_DOUBLE_EQ(eps * friction_mollifier_slope_over_y(eps, eps), 1);
  EXPECT_DOUBLE_EQ(friction_mollifier_slope_over_y(0, eps), 2 / eps);
}

// Both branches: slips well below ε (all pairs sticking) and well beyond it (all sliding).
TEST(Friction, DerivativesMatchCentralDifferencesStickingAndSliding) {
  const Scenario s;
  std::mt19937 rng(5);
  struct Case {
    double slip;
    Vec3 shift;
    double amount;
    bool sliding;
  };
  for (const Case& c : {Case{1e-3, Vec3::Zero(), 1e-4, false},
                        Case{1e-4, Vec3(0.003, 0.002, 0.0015), 2e-4, true}}) {
    const Lagged l = lagged_state(s, c.shift, c.amount, rng);
    std::vector<ContactPair> pairs = s.contact.pairs(l.anchor);
    expect_every_pair_kind(pairs);
    const ObstacleFriction friction(s.contact, std::move(pairs), l.anchor, 0.4, c.slip);
    for (std::size_t k = 0; k < friction.pairs().size(); ++k) {
      const double y = friction.slip(l.x, k).norm();
      if (c.sliding) EXPECT_GT(y, 2 * c.slip) << "pair " << k;
      else EXPECT_LT(y, 0.5 * c.slip) << "pair " << k;
    }
    test::expect_derivatives_match(friction, l.x, 1e-5);
    // PSD as it stands: the projection changes nothing.
    const Eigen::MatrixXd H = test::dense_hessian(friction, l.x);
    EXPECT_LT((test::dense_hessian(friction, l.x, true) - H).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff(),
              -1e-9 * H.cwiseAbs().maxCoeff());
  }
}

// λ, n and w of every pair as one vector (the pairs must be the same ones wherever it is taken).
Eigen::VectorXd lagged_quantities(const std::vector<ContactPair>& pairs) {
  Eigen::VectorXd out(7 * pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const ContactPair& p = pairs[k];
    out[7 * k] = p.force;
    out.segment<3>(7 * k + 1) = p.normal;
    for (int a = 0; a < 3; ++a) out[7 * k + 4 + a] = a < p.node_count ? p.weights[a] : 0.0;
  }
  return out;
}

TEST(Friction, PairDerivativesMatchCentralDifferences) {
  const Scenario s;
  std::mt19937 rng(11);
  const Lagged l = lagged_state(s, Vec3::Zero(), 1e-4, rng);
  const std::vector<ContactPairDerivatives> jets = s.contact.pair_derivatives(l.x);
  const std::size_t count = jets.size();
  Eigen::MatrixXd analytic = Eigen::MatrixXd::Zero(7 * count, l.x.size());
  std::vector<ContactPair> pairs;
  for (std::size_t k = 0; k < count; ++k) {
    const ContactPairDerivatives& j = jets[k];
    pairs.push_back(j.pair);
    for (int c = 0; c < j.pair.node_count; ++c) {
      const auto columns = [&](const auto& m) { return m.middleCols(3 * c, 3); };
      analytic.block(7 * k, 3 * j.pair.nodes[c], 1, 3) = columns(j.force);
      analytic.block(7 * k + 1, 3 * j.pair.nodes[c], 3, 3) = columns(j.normal);
      analytic.block(7 * k + 4, 3 * j.pair.nodes[c], 3, 3) = columns(j.weights);
    }
  }
  expect_every_pair_kind(pairs);
  const auto quantities = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    const std::vector<ContactPair> at = s.contact.pairs(y);
    EXPECT_EQ(at.size(), count);
    return at.size() == count ? lagged_quantities(at) : Eigen::VectorXd::Zero(7 * count);
  };
  EXPECT_TRUE(test::derivative_matches(analytic,
                                       test::central_difference_jacobian(quantities, l.x, 1e-7),
                                       1e-5, "∂(λ, n, w)/∂x"));
}

// The force of friction lagged wherever it is evaluated, ∇ₓD(x; lag(x)): its Jacobian is the
// Hessian at fixed lag plus the lag Jacobian. Sticking and sliding.
TEST(Friction, LagJacobianMatchesCentralDifferencesOfTheRelaggedForce) {
  const Scenario s;
  std::mt19937 rng(13);
  const double mu = 0.4;
  for (const auto& [slip, shift] :
       {std::pair{1e-3, Vec3(Vec3::Zero())}, std::pair{1e-4, Vec3(0.003, 0.002, 0.0015)}}) {
    const Lagged l = lagged_state(s, shift, 1e-4, rng);
    const auto relagged_force = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
      return test::energy_gradient(ObstacleFriction(s.contact, s.contact.pairs(y), l.anchor, mu,
                                                    slip),
                                   y);
    };
    const ObstacleFriction at_x(s.contact, s.contact.pairs(l.x), l.anchor, mu, slip);
    const Triplets t =
        friction_lag_jacobian(s.contact.pair_derivatives(l.x), l.anchor, l.x, mu, slip);
    SparseMatrix lag(l.x.size(), l.x.size());
    lag.setFromTriplets(t.begin(), t.end());
    const Eigen::MatrixXd fixed_lag = test::dense_hessian(at_x, l.x);
    const Eigen::MatrixXd reference = test::central_difference_jacobian(relagged_force, l.x, 1e-7);
    const std::string what = "∂/∂x ∇D(x; lag(x)), slip length " + std::to_string(slip);
    const auto check =
        test::derivative_matches(fixed_lag + Eigen::MatrixXd(lag), reference, 1e-5, what);
    std::cout << check.message() << "\n";
    EXPECT_TRUE(check);
    // Without L the same check fails: the lag's part is no round-off.
    EXPECT_FALSE(test::derivative_matches(fixed_lag, reference, 1e-5, what + " at fixed lag"));
  }
}

TEST(Friction, HessianElementsAreTheContactsWhateverIsLagged) {
  const Scenario s;
  ElementNodes contact, none, some;
  const Positions x = s.mesh.rest_vector();
  s.contact.hessian_elements(x, contact);
  ObstacleFriction(s.contact, {}, x, 0.5, 1e-4).hessian_elements(x, none);
  ObstacleFriction(s.contact, s.contact.pairs(x), x, 0.5, 1e-4).hessian_elements(x, some);
  EXPECT_EQ(none, contact);
  EXPECT_EQ(some, contact);
}

// The whole box slid along the table by many ε: every pair pushes back with μλ, against the
// motion, and nothing along the normal.
TEST(Friction, ASlideIsResistedByMuTimesTheNormalForce) {
  const TetMesh mesh = make_box_mesh({0.1, 0.1, 0.02}, {4, 4, 1});
  const ObstacleContact contact(
      mesh, {make_plane("table", Vec3(0, 0, -0.01 - 0.4 * kDhat), Vec3(0, 0, 1))}, kDhat, 3.0);
  const Positions anchor = mesh.rest_vector();
  const std::vector<ContactPair> pairs = contact.pairs(anchor);
  ASSERT_FALSE(pairs.empty());
  double normal = 0;
  for (const ContactPair& p : pairs) normal += p.force;
  const double mu = 0.3, eps = 1e-5;
  const ObstacleFriction friction(contact, pairs, anchor, mu, eps);
  const Vec3 direction = Vec3(3, 4, 0).normalized();
  Positions x = anchor;
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) += 100 * eps * direction;
  const Eigen::VectorXd g = test::energy_gradient(friction, x);
  Vec3 force = Vec3::Zero();
  for (int i = 0; i < mesh.node_count(); ++i) force -= g.segment<3>(3 * i);
  EXPECT_NEAR(force.dot(-direction), mu * normal, 1e-12 * mu * normal);
  EXPECT_LT((force + mu * normal * direction).norm(), 1e-12 * mu * normal);
  // Half an ε: it sticks, with less than μλ.
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) = anchor.segment<3>(3 * i);
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) += 0.5 * eps * direction;
  force = -test::energy_gradient(friction, x).reshaped(3, mesh.node_count()).rowwise().sum();
  EXPECT_NEAR(force.dot(-direction), 0.75 * mu * normal, 1e-12 * mu * normal);  // f₁(ε/2) = 3/4
}

}  // namespace
}  // namespace shapectl
