#pragma once
// dx̂/dθ at a converged state against central differences of equilibria re-solved at θ ± h
// (each warm-started from the state's positions, at its contact stiffness: the derivative of
// the equilibrium map at that κ), and the adjoint against (dx̂/dθ)ᵀ v.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include <shapectl/sim/gripped_object.hpp>

#include "support/derivative_check.hpp"

namespace shapectl::test {

inline void expect_sensitivity_matches(const GrippedObject& object, ObjectState& state,
                                       double tolerance, const std::string& what) {
  const Positions x = state.positions();
  const Eigen::VectorXd theta = state.joints();
  const Eigen::MatrixXd dx = object.sensitivity(state);
  const auto equilibrium = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    ObjectState moved = object.make_state(t, x, nullptr, state.contact_scale());
    object.solve(moved, t);
    EXPECT_TRUE(moved.statics().converged()) << moved.statics().reason;
    EXPECT_EQ(moved.contact_scale(), state.contact_scale()) << "raised again";
    return moved.positions();
  };
  EXPECT_TRUE(derivative_matches(dx, central_difference_jacobian(equilibrium, theta, 1e-5),
                                 tolerance, "dx/dθ " + what));
  std::mt19937 rng(5);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 1.0, rng);
  EXPECT_TRUE(derivative_matches(object.adjoint(state, v), dx.transpose() * v, 1e-9,
                                 "adjoint (dx/dθ)ᵀv " + what));
}

}  // namespace shapectl::test
