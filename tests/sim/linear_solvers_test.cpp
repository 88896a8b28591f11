#include <gtest/gtest.h>

#include <optional>
#include <random>

#include <shapectl/linalg/own_kernel_calls.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "support/linear_solvers.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

// A foam bar clamped at its -x end.
Scene clamped_bar() {
  Scene s;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, {16, 4, 4}));
  s.material = material_from_youngs(2e5, 0.3, 40);
  NodeSelection fixed;
  fixed.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-0.16 + 1e-3, 1, 1)};
  s.fixed = fixed;
  return s;
}

TEST(SparseCholesky, StaticsReachesTheSameEquilibriumWithEveryBackend) {
  std::vector<Positions> results;
  for (const CholeskyBackend backend : test::kLinearSolvers) {
    const Scene scene = test::with_solver(clamped_bar(), backend);
    ObjectStatics statics(scene);
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    ASSERT_TRUE(r.converged()) << to_string(backend) << ": " << r.reason;
    results.push_back(x);
  }
  for (std::size_t k = 1; k < results.size(); ++k)
    EXPECT_LT((results[k] - results[0]).cwiseAbs().maxCoeff(), 1e-8)
        << to_string(test::kLinearSolvers[k]);
}

// The count of calls into our own kernels over a held bar's statics, its sensitivities and an
// adjoint solve, with `backend` (none: the automatic choice).
std::uint64_t own_kernel_calls_solving_with(std::optional<CholeskyBackend> backend) {
  Scene scene = test::two_arm_scene();
  scene.statics.backend = backend;
  const GrippedObject object(scene);
  std::mt19937 rng(7);
  Eigen::VectorXd theta = object.reference_joints();
  for (int j = 0; j < theta.size(); ++j) theta[j] += std::uniform_real_distribution(-0.2, 0.2)(rng);
  const std::uint64_t before = own_kernel_calls();
  ObjectState state = object.solve_from(theta, object.reference_positions());
  EXPECT_TRUE(state.statics().converged()) << state.statics().reason;
  const Eigen::MatrixXd dx = object.sensitivity(state);
  const Eigen::VectorXd v = Eigen::VectorXd::Ones(dx.rows());
  const Eigen::VectorXd dx_v = dx.transpose() * v;
  EXPECT_LT((object.adjoint(state, v) - dx_v).norm(), 1e-9 * dx_v.norm());
  return own_kernel_calls() - before;
}

TEST(CholmodLibrary, NeverEntersOurKernels) {
  EXPECT_EQ(own_kernel_calls_solving_with(CholeskyBackend::CholmodLibrary), 0u);
  // The counter does count: our supernodal back-end, on the same work, moves it, and so does
  // the automatic choice (the band, on this bar), so the scene's back-end is not ignored.
  EXPECT_GT(own_kernel_calls_solving_with(CholeskyBackend::CholmodSupernodal), 0u);
  EXPECT_GT(own_kernel_calls_solving_with(std::nullopt), 0u);
}

}  // namespace
}  // namespace shapectl
