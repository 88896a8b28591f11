#include <shapectl/control/reduced_objective.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <shapectl/io/input_error.hpp>

#include "support/derivative_check.hpp"
#include "support/linear_solvers.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

ShapeTargets some_targets(const GrippedObject& object, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  ShapeTargets t;
  const Positions x0 = object.reference_positions();
  for (int i = 0; i < object.node_count(); i += 5) {
    t.nodes.push_back(i);
    t.positions.push_back(x0.segment<3>(3 * i) + Vec3(u(rng), u(rng), u(rng)));
  }
  return t;
}

// Gradients from each linear solver's factor (support/linear_solvers.hpp).
class ReducedObjectiveEachSolver : public test::EachLinearSolver {};

TEST_P(ReducedObjectiveEachSolver, GradientAgreesAllThreeWaysWithCentralDifferences) {
  Scene scene = with_solver(test::two_arm_scene());
  scene.statics.relative_tolerance = 1e-11;
  GrippedObject object(scene);
  std::mt19937 rng(11);
  // Exact sensitivities for this comparison.
  const ReducedObjective objective(object, some_targets(object, rng),
                                   {.finite_difference_step = 1e-6, .stale_factor_step = 0});
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd theta = object.reference_joints();
    for (int j = 0; j < theta.size(); ++j) theta[j] += u(rng);
    theta[1] = 1.97;  // inside the joint-limit margin: the barrier contributes
    Evaluation at = objective.evaluate(theta, object.reference_positions());
    ASSERT_TRUE(at.statics().converged());
    ASSERT_GT(at.joint_limits, 0);
    // Ô with the equilibrium re-solved at each perturbed θ.
    const auto reduced = [&](const Eigen::VectorXd& t) {
      return objective.evaluate(t, at.positions()).objective;
    };
    const Eigen::VectorXd central = test::central_difference_gradient(reduced, theta, 1e-5);
    const Eigen::VectorXd sensitivity = objective.gradient(at, GradientMethod::Sensitivity);
    const Eigen::VectorXd adjoint = objective.gradient(at, GradientMethod::Adjoint);
    const Eigen::VectorXd forward = objective.gradient(at, GradientMethod::FiniteDifference);
    EXPECT_TRUE(test::derivative_matches(sensitivity, central, 1e-5, "sensitivity gradient"))
        << "trial " << trial;
    EXPECT_TRUE(test::derivative_matches(adjoint, central, 1e-5, "adjoint gradient"))
        << "trial " << trial;
    // Forward differences carry an O(h) error: the baseline is less exact by nature.
    EXPECT_TRUE(test::derivative_matches(forward, central, 1e-3, "forward-difference gradient"))
        << "trial " << trial;
  }
}

TEST_P(ReducedObjectiveEachSolver, LeastSquaresFormMatchesObjectiveAndGradient) {
  Scene scene = with_solver(test::two_arm_scene());
  scene.statics.relative_tolerance = 1e-11;
  GrippedObject object(scene);
  std::mt19937 rng(12);
  const ReducedObjective objective(object, some_targets(object, rng), {.stale_factor_step = 0});
  Eigen::VectorXd theta = object.reference_joints();
  theta[4] = -1.97;  // near the lower limit
  Evaluation at = objective.evaluate(theta, object.reference_positions());
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  objective.least_squares(at, r, J);
  EXPECT_NEAR(0.5 * r.squaredNorm(), at.objective, 1e-12 * at.objective);
  EXPECT_TRUE(test::derivative_matches(J.transpose() * r,
                                       objective.gradient(at, GradientMethod::Sensitivity), 1e-9,
                                       "Jᵀr against the gradient"));
  // The Jacobian itself against central differences of the residuals.
  const auto residuals = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    Eigen::VectorXd residual;
    Eigen::MatrixXd unused;
    Evaluation e = objective.evaluate(t, at.positions());
    objective.least_squares(e, residual, unused);
    return residual;
  };
  EXPECT_TRUE(test::derivative_matches(J, test::central_difference_jacobian(residuals, theta, 1e-6),
                                       1e-5, "least-squares Jacobian"));
}

INSTANTIATE_TEST_SUITE_P(Each, ReducedObjectiveEachSolver, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

TEST(ReducedObjective, ConfirmStableRejectsAStateWhoseHessianIsIndefinite) {
  const Scene scene = test::two_arm_scene();
  GrippedObject object(scene);
  ReducedObjective objective(object);
  Evaluation held = objective.evaluate(object.reference_joints(), object.reference_positions());
  ASSERT_TRUE(held.statics().converged());
  EXPECT_TRUE(objective.confirm_stable(held));
  EXPECT_EQ(held.statics().status, StaticsStatus::Converged);
  // The same bar shortened 10 % along its axis, straight: ten times its Euler buckling strain,
  // so bending has negative stiffness there. Solved by an object whose force tolerance passes
  // any state, so that the state is a converged one (its own: the mark goes into the state).
  Positions x = held.positions();
  const Vec3 centre = scene.T_world_object.translation();
  const Vec3 axis = scene.T_world_object.linear().col(0);
  for (int i = 0; i < object.node_count(); ++i) {
    const Vec3 p = x.segment<3>(3 * i);
    x.segment<3>(3 * i) = p - 0.1 * axis.dot(p - centre) * axis;
  }
  Scene loose_scene = scene;
  loose_scene.statics.relative_tolerance = 1e12;
  GrippedObject loose(loose_scene);
  ReducedObjective loose_objective(loose);
  Evaluation squeezed = loose_objective.evaluate(held.joints(), x);
  ASSERT_TRUE(squeezed.statics().converged());
  ASSERT_EQ(squeezed.statics().iterations, 0);
  EXPECT_FALSE(loose_objective.confirm_stable(squeezed));
  EXPECT_EQ(squeezed.statics().status, StaticsStatus::Unstable);
  EXPECT_EQ(squeezed.state->statics().status, StaticsStatus::Unstable);
  EXPECT_FALSE(std::isfinite(squeezed.objective));
  EXPECT_FALSE(squeezed.safe());
  // A copy reads the same state, mark included; `held` has a state of its own.
  const Evaluation copy = squeezed;
  EXPECT_EQ(copy.statics().status, StaticsStatus::Unstable);
  EXPECT_EQ(held.statics().status, StaticsStatus::Converged);
}

TEST(ReducedObjective, AbsurdTargetsAreRefusedNamingTheTargetAndChangeNothing) {
  GrippedObject object(test::two_arm_scene());
  ReducedObjective objective(object);
  ShapeTargets good;
  good.nodes = {0, 5};
  good.positions = {Vec3(0.1, 0, 0.2), Vec3(0.2, 0, 0.2)};
  objective = objective.with_targets(good);
  const std::vector<std::pair<ShapeTargets, std::string>> bad = {
      {{{0, 5}, {Vec3(0, 0, 0), Vec3(1e155, 0, 0)}},
       "targets: targets[1].position: expected a finite point within 1000 m of the origin, got "
       "[1e+155, 0, 0]"},
      {{{0}, {Vec3(0, -1e300, 0)}}, "targets[0].position: expected a finite point within 1000 m"},
      {{{0}, {Vec3(0, 0, NAN)}}, "targets[0].position: expected a finite point"},
      {{{0}, {Vec3(1000.5, 0, 0)}}, "targets[0].position: expected a finite point within 1000 m"},
      {{{object.node_count()}, {Vec3(0, 0, 0)}},
       "targets[0].node: expected a node from 0 to " + std::to_string(object.node_count() - 1)},
      {{{0, 1}, {Vec3(0, 0, 0)}}, "targets: expected as many positions as nodes"}};
  for (const auto& [targets, message] : bad) {
    try {
      objective = objective.with_targets(targets);
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
    EXPECT_EQ(objective.targets().nodes, good.nodes);
  }
  // The bound itself is a valid target.
  objective = objective.with_targets({{0}, {Vec3(-1000, 1000, 0)}});
  EXPECT_EQ(objective.targets().size(), 1);
}

}  // namespace
}  // namespace shapectl
