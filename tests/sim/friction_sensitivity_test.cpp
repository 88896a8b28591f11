// dx̂/dθ with friction (issue 34): a bar gripped by two arms, its middle on a table with
// friction, swung a little (its contacts stick) or far (they slide) from the equilibrium before.
// The sensitivity at the lagged solve's fixed point against central differences of the whole
// lagged solve from the same warm start (its anchor), and the adjoint against it. The Hessian
// without friction, and the one with friction at fixed lag (no lag Jacobian), are measured on
// the same check: they must fail it, or the check could not tell.
#include <shapectl/sim/friction_sensitivity.hpp>

#include <gtest/gtest.h>

#include <iostream>
#include <random>

#include <shapectl/sim/gripped_object.hpp>

#include "support/derivative_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

Scene bar_on_table(double friction) {
  Scene scene = test::two_arm_scene({12, 2, 2});
  test::add_table_under(scene, 0.5e-3);
  scene.contact.distance = 1e-3;
  scene.contact.friction = friction;
  scene.statics.relative_tolerance = 1e-8;  // FD of equilibria needs them tight (1e-10: round-off)
  scene.statics.max_iterations = 300;
  return scene;
}

// The equilibrium at θ⁰ lowered by 4 mrad per arm (pressed onto the table), then both arms
// swung about z by `swing`: the state there and its warm start (the anchor).
struct Dragged {
  Positions anchor;
  ObjectState state;
};
Dragged drag(const GrippedObject& object, double swing) {
  Eigen::VectorXd lowered = object.reference_joints();
  lowered[1] += 0.004, lowered[4] += 0.004;
  const ObjectState before = object.solve_from(lowered, object.reference_positions());
  EXPECT_TRUE(before.statics().converged()) << before.statics().reason;
  Eigen::VectorXd joints = lowered;
  joints[0] += swing, joints[3] += swing;
  Positions x = before.positions();
  object.carry_gripped_nodes(before.joints(), joints, before.positions(), x);
  ObjectState state = object.solve_from(joints, x, 0, &before);
  EXPECT_TRUE(state.statics().converged()) << state.statics().reason;
  return {x, std::move(state)};
}

// dx̂/dθ with H factored from `terms` (the Hessian alone, no lag Jacobian).
Eigen::MatrixXd hessian_sensitivity(const GrippedObject& object, const ObjectState& state,
                                    EnergyTerms terms) {
  const GripEnergy grip(object.grips(), state.kinematics());
  terms.push_back(&grip);
  StaticsWorkspace ws = object.statics().make_workspace();
  EXPECT_TRUE(object.statics().solver().factor(terms, ws, state.positions()));
  return object.statics().solver().solve_with_factor(ws, object.force_jacobian(state));
}

void expect_exact_with_friction(double swing, bool sticking) {
  const GrippedObject object(bar_on_table(1.0));
  Dragged d = drag(object, swing);
  ASSERT_TRUE(d.state.statics().converged());
  const FixedPointFriction friction =
      fixed_point_friction(*object.contact_at(d.state), object.statics().friction(), d.anchor,
                           d.state.positions());
  int stick = 0, slide = 0;
  for (std::size_t k = 0; k < friction.term.pairs().size(); ++k)
    ++(friction.term.slip(d.state.positions(), k).norm() < object.statics().friction().slip
           ? stick
           : slide);
  std::cout << "swing " << swing << " rad: " << stick << " pairs sticking, " << slide
            << " sliding; contact stiffness ×" << d.state.contact_scale() << "; "
            << d.state.statics().reason << "\n";
  // Sticking: nearly all; sliding: most (the pairs beside the grips stick, 6 of 17 at the
  // stiffness the adaptive barrier raises this scene to).
  if (sticking) EXPECT_GT(stick, 2 * slide);
  else EXPECT_GT(slide, stick);

  const Eigen::MatrixXd dx = object.sensitivity(d.state);
  const auto equilibrium = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    // The same anchor, at the state's contact stiffness (the derivative at that κ).
    ObjectState moved = object.make_state(t, d.anchor, nullptr, d.state.contact_scale());
    object.solve(moved, t);
    EXPECT_EQ(moved.contact_scale(), d.state.contact_scale()) << "raised again";
    EXPECT_TRUE(moved.statics().converged()) << moved.statics().reason;
    return moved.positions();
  };
  const Eigen::MatrixXd reference =
      test::central_difference_jacobian(equilibrium, d.state.joints(), 1e-6);
  const double tolerance = 1e-5;  // 1e-7 sticking, 5e-7 sliding on the 2026-11-29 run
  const auto exact = test::derivative_matches(dx, reference, tolerance, "dx/dθ with friction");
  std::cout << exact.message() << "\n";
  EXPECT_TRUE(exact);

  // Without friction's Hessian, and with it at fixed lag: the same check fails.
  const ContactTerms at_scale = object.statics().contact_terms(d.state.contact_scale());
  const EnergyTerms frictionless = object.statics().terms(nullptr, at_scale);
  EnergyTerms fixed_lag = frictionless;
  fixed_lag.push_back(&friction.term);
  for (const auto& [what, terms] : {std::pair{"frictionless Hessian", frictionless},
                                    std::pair{"friction at fixed lag", fixed_lag}}) {
    const auto wrong = test::derivative_matches(hessian_sensitivity(object, d.state, terms),
                                                reference, tolerance, what);
    std::cout << wrong.message() << "\n";
    EXPECT_FALSE(wrong);
  }

  std::mt19937 rng(5);
  const Eigen::VectorXd v = test::perturbed(Eigen::VectorXd::Zero(dx.rows()), 1.0, rng);
  EXPECT_TRUE(test::derivative_matches(object.adjoint(d.state, v), dx.transpose() * v, 1e-9,
                                       "adjoint (dx/dθ)ᵀv with friction"));
}

TEST(FrictionSensitivity, MatchesTheLaggedSolveWhereTheContactsStick) {
  expect_exact_with_friction(2e-5, true);
}

TEST(FrictionSensitivity, MatchesTheLaggedSolveWhereTheContactsSlide) {
  expect_exact_with_friction(0.01, false);
}

}  // namespace
}  // namespace shapectl
