#pragma once
// The linear solvers ("statics.linear_solver") that parametrized suites run with: each of our
// back-ends and CHOLMOD on its own, so that statics, derivative and reachability tests show the
// answer does not depend on which one factors (`auto` picks band or LDLᵀ on the small test
// meshes, and never CHOLMOD's own).
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include <shapectl/linalg/cholesky_backend.hpp>
#include <shapectl/sim/scene.hpp>

namespace shapectl::test {

inline constexpr CholeskyBackend kLinearSolvers[] = {CholeskyBackend::SimplicialLDLT,
                                                     CholeskyBackend::Band,
                                                     CholeskyBackend::CholmodSupernodal,
                                                     CholeskyBackend::CholmodLibrary};

// A test name's suffix: the scene-file name with '_' for '-' (GoogleTest allows no '-').
inline std::string linear_solver_suffix(CholeskyBackend backend) {
  std::string name = to_string(backend);
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}
// The name generator of INSTANTIATE_TEST_SUITE_P over kLinearSolvers.
inline std::string linear_solver_name(const testing::TestParamInfo<CholeskyBackend>& info) {
  return linear_solver_suffix(info.param);
}

// Whether `backend` calls a matrix singular when a pivot is tiny next to the largest (LDLᵀ and
// the band do). CHOLMOD's factorizations, ours and its own, refuse only non-positive pivots: a
// singular or ill-conditioned Hessian may factor, and Newton then ends "not converged" where
// the others say "singular".
inline bool refuses_tiny_pivots(CholeskyBackend backend) {
  return backend == CholeskyBackend::SimplicialLDLT || backend == CholeskyBackend::Band;
}

// `scene` with its statics factored by `backend`.
inline Scene with_solver(Scene scene, CholeskyBackend backend) {
  scene.statics.backend = backend;
  return scene;
}

// A suite run once per linear solver: INSTANTIATE_TEST_SUITE_P(Each, Suite,
// testing::ValuesIn(kLinearSolvers), linear_solver_name).
class EachLinearSolver : public testing::TestWithParam<CholeskyBackend> {
 protected:
  Scene with_solver(Scene scene) const { return test::with_solver(std::move(scene), GetParam()); }
};

}  // namespace shapectl::test
