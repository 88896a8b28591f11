// The workspace pool on the state side: a workspace goes back to a solver of its own shape
// only, and reusing one changes no equilibrium.
#include <shapectl/sim/workspace_pool.hpp>

#include <gtest/gtest.h>

#include <shapectl/sim/gripped_object.hpp>

#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

long long analyses() { return statics_totals().analyses; }

TEST(WorkspacePool, AWorkspaceIsReusedOnlyForItsFixedNodesAndChangesNoEquilibrium) {
  const Scene scene = test::two_arm_scene();
  Scene pinned = scene;  // the same mesh and grips, one more node fixed: other fixed dofs
  pinned.fixed = NodeSelection{.box = std::nullopt, .nodes = {scene.object_mesh->node_count() / 2}};
  const GrippedObject a(scene), b(pinned);
  const Eigen::VectorXd theta =
      a.reference_joints() + Eigen::VectorXd::Constant(a.joint_count(), 0.05);
  // Each on a workspace of its own: the reference.
  const Positions alone_a = a.solve_from(theta, a.reference_positions()).positions();
  const Positions alone_b = b.solve_from(theta, b.reference_positions()).positions();
  ASSERT_NE(alone_a, alone_b);

  const auto pool = WorkspacePool::create();
  long long before = analyses();
  Positions pooled_a =
      a.solve_from(theta, a.reference_positions(), 0, nullptr, {}, pool).positions();
  EXPECT_EQ(analyses() - before, 1);  // a new workspace
  EXPECT_EQ(pooled_a, alone_a);
  // a's workspace is free again, but not of b's shape: b gets a new one.
  before = analyses();
  const ObjectState pooled_b = b.solve_from(theta, b.reference_positions(), 0, nullptr, {}, pool);
  EXPECT_EQ(analyses() - before, 1);
  EXPECT_EQ(pooled_b.positions(), alone_b);
  // a's comes back to a (b's is still held), analysis and all.
  before = analyses();
  pooled_a = a.solve_from(theta, a.reference_positions(), 0, nullptr, {}, pool).positions();
  EXPECT_EQ(analyses() - before, 0);
  EXPECT_EQ(pooled_a, alone_a);
}

TEST(WorkspacePool, SolversOfOtherShapesGetOtherWorkspaces) {
  const StaticsSolver solver(4, {1, 0, 0, 0});
  const StaticsSolver other_fixed(4, {0, 0, 0, 1});
  const StaticsSolver other_size(5, {1, 0, 0, 0, 0});
  const StaticsSolver other_backend(4, {1, 0, 0, 0}, {.backend = CholeskyBackend::Band});
  const auto pool = WorkspacePool::create();
  const StaticsWorkspace* first = pool->acquire(solver).get();  // released at once
  for (const StaticsSolver* s : {&other_fixed, &other_size, &other_backend}) {
    const auto ws = pool->acquire(*s);
    EXPECT_NE(ws.get(), first);
  }
  EXPECT_EQ(pool->acquire(solver).get(), first);
}

}  // namespace
}  // namespace shapectl
