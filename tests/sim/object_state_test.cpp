// Model and data: one GrippedObject shared by threads, each with states of its own, gives
// exactly what serial runs give.
#include <shapectl/sim/gripped_object.hpp>

#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

struct PathRun {
  std::vector<Positions> positions;
  std::vector<Eigen::MatrixXd> sensitivities;
  std::vector<Eigen::VectorXd> adjoints;
};

std::vector<Eigen::VectorXd> joint_path(const GrippedObject& object, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  std::vector<Eigen::VectorXd> path;
  Eigen::VectorXd theta = object.reference_joints();
  for (int k = 0; k < 6; ++k) {
    for (int j = 0; j < theta.size(); ++j) theta[j] += u(rng);
    path.push_back(theta);
  }
  return path;
}

// Follows `path` with one state, warm start and chord steps from the previous θ, as an
// optimizer does; records the equilibria and their derivatives.
PathRun follow(const GrippedObject& object, const std::vector<Eigen::VectorXd>& path) {
  PathRun run;
  ObjectState state = object.make_state(object.reference_joints(), object.reference_positions());
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(3 * object.node_count(), -1, 1);
  for (const auto& theta : path) {
    const StaticsResult& r = object.solve(state, theta, 0, &state);
    EXPECT_TRUE(r.converged()) << r.reason;
    run.positions.push_back(state.positions());
    run.sensitivities.push_back(object.sensitivity(state, 1e-6));
    run.adjoints.push_back(object.adjoint(state, v, 1e-6));
  }
  return run;
}

void expect_identical(const PathRun& a, const PathRun& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t k = 0; k < a.positions.size(); ++k) {
    EXPECT_TRUE(a.positions[k] == b.positions[k]) << "positions differ at step " << k;
    EXPECT_TRUE(a.sensitivities[k] == b.sensitivities[k]) << "dx/dθ differs at step " << k;
    EXPECT_TRUE(a.adjoints[k] == b.adjoints[k]) << "adjoint differs at step " << k;
  }
}

TEST(ObjectState, TwoThreadsOnOneModelGiveTheSerialResultsBitForBit) {
  const GrippedObject object(test::two_arm_scene());
  const auto path_a = joint_path(object, 1), path_b = joint_path(object, 2);
  const PathRun serial_a = follow(object, path_a), serial_b = follow(object, path_b);
  // The paths differ: the comparison below could fail.
  ASSERT_FALSE(serial_a.positions.back() == serial_b.positions.back());
  for (int round = 0; round < 3; ++round) {
    PathRun parallel_a, parallel_b;
    std::thread a([&] { parallel_a = follow(object, path_a); });
    std::thread b([&] { parallel_b = follow(object, path_b); });
    a.join();
    b.join();
    expect_identical(parallel_a, serial_a);
    expect_identical(parallel_b, serial_b);
  }
}

TEST(ObjectState, AStateSolvedAgainAtItsEquilibriumNeedsNoStepAndKeepsItsFactor) {
  const GrippedObject object(test::two_arm_scene());
  ObjectState state = object.solve_from(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(state.statics().converged());
  const Positions before = state.positions();
  const StaticsResult& again = object.solve(state, object.reference_joints(), 0, &state);
  EXPECT_TRUE(again.converged());
  EXPECT_EQ(again.iterations, 0);
  EXPECT_EQ(again.factorizations, 0);
  EXPECT_TRUE(state.positions() == before);
  EXPECT_TRUE(state.has_factor());
}

TEST(ObjectState, ChordStepsComeOnlyFromTheStateNamed) {
  // The same solve with and without a chord source: chord steps save factorizations only when
  // a nearby state's factorization is given; none is remembered from earlier calls.
  const GrippedObject object(test::two_arm_scene());
  const ObjectState start =
      object.solve_from(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(start.has_factor());
  Eigen::VectorXd theta = object.reference_joints();
  theta.array() += 0.01;
  const ObjectState plain = object.solve_from(theta, start.positions());
  const ObjectState chord = object.solve_from(theta, start.positions(), 0, &start);
  const ObjectState plain_again = object.solve_from(theta, start.positions());
  ASSERT_TRUE(plain.statics().converged() && chord.statics().converged());
  EXPECT_LT(chord.statics().factorizations, plain.statics().factorizations);
  EXPECT_EQ(plain_again.statics().factorizations, plain.statics().factorizations);
  EXPECT_TRUE(plain_again.positions() == plain.positions());
}

}  // namespace
}  // namespace shapectl
