// Statics reports only what it found: never "converged" with non-finite numbers, and a
// singular system says whether nothing holds the object or the numbers are ill-conditioned.
#include <shapectl/sim/gripped_object.hpp>
#include <shapectl/sim/object_statics.hpp>

#include <gtest/gtest.h>

#include <cmath>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/linear_solvers.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

Scene clamped_bar(double youngs, double density) {
  Scene s;
  s.source = "clamped_bar";
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, {8, 2, 2}));
  s.material = material_from_youngs(youngs, 0.3, density);
  s.fixed = NodeSelection{.box = AlignedBox{Vec3(-0.161, -0.02, -0.02), Vec3(-0.139, 0.02, 0.02)},
                          .nodes = {}};
  return s;
}

// Each check with each linear solver (support/linear_solvers.hpp).
class StaticsHonesty : public test::EachLinearSolver {};

TEST_P(StaticsHonesty, AbsurdGravityIsNeverReportedConverged) {
  // 1e300 overflows the weight, 1e150 the energy of the first Newton step.
  for (double g : {1e300, 1e200, 1e150}) {
    Scene scene = with_solver(clamped_bar(2e5, 40));
    scene.gravity = Vec3(0, 0, -g);
    ObjectStatics statics(scene);
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    EXPECT_FALSE(r.converged()) << "gravity " << g << ": " << r.reason;
    EXPECT_EQ(r.status, StaticsStatus::NotConverged) << r.reason;
  }
}

TEST_P(StaticsHonesty, ConvergedMeansFiniteResidualEnergyAndPositions) {
  for (double g : {9.81, 1e6, 1e12}) {
    Scene scene = with_solver(clamped_bar(2e5, 40));
    scene.gravity = Vec3(0, 0, -g);
    ObjectStatics statics(scene);
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    if (g == 9.81) {
      EXPECT_TRUE(r.converged()) << r.reason;  // so the checks below run
    }
    if (!r.converged()) continue;
    EXPECT_TRUE(std::isfinite(r.residual) && std::isfinite(r.energy) && x.allFinite()) << g;
    EXPECT_LE(r.residual, statics.force_tolerance()) << g;
  }
}

// A scene built in code skips load_scene's refusal (scene_io): the solver's own floor still
// stays below a share of a node's load, so the rest shape never passes as the equilibrium.
TEST_P(StaticsHonesty, NearlyIncompressibleMaterialIsNeverConvergedAtRest) {
  for (double gap : {1e-6, 1e-10, 1e-13}) {  // 0.5 - nu
    Scene scene = with_solver(clamped_bar(2e5, 40));
    scene.material = material_from_youngs(2e5, 0.5 - gap, 40);
    ObjectStatics statics(scene);
    const double nodal_load = statics.weight() / statics.mesh().node_count();
    EXPECT_LE(statics.force_tolerance(), max_roundoff_share * nodal_load) << gap;
    Positions x = scene.world_rest_positions();
    const StaticsResult r = statics.solve(x);
    // load_scene accepts the first, refuses the others.
    EXPECT_EQ(roundoff_load_ratio(scene, scene.material) <= 1, gap == 1e-6) << gap;
    if (gap == 1e-6) {
      EXPECT_TRUE(r.converged()) << r.reason;
    }
    if (r.converged()) {
      EXPECT_GT(r.iterations, 0) << gap << ": " << r.reason;
    }
  }
}

GrippedObject held_bar(double youngs, CholeskyBackend backend) {
  Scene scene = test::with_solver(test::two_arm_scene({12, 2, 2}), backend);
  scene.material = material_from_youngs(youngs, 0.3, 40);
  return GrippedObject(scene);
}

TEST_P(StaticsHonesty, ExtremeMaterialOfAHeldObjectIsNotCalledUnheld) {
  // 1 mPa foam in 1e4 N/m grips: stiffnesses 16 orders apart, beyond what doubles resolve.
  GrippedObject object = held_bar(1e-3, GetParam());
  const ObjectState state =
      object.solve_from(object.reference_joints(), object.reference_positions());
  const StaticsResult& r = state.statics();
  const Positions& x = state.positions();
  EXPECT_FALSE(r.converged()) << r.reason;
  EXPECT_EQ(r.reason.find("held"), std::string::npos) << r.reason;
  EXPECT_TRUE(x.allFinite());
  if (!test::refuses_tiny_pivots(GetParam())) return;  // CHOLMOD factors it: "not converged"
  ASSERT_EQ(r.status, StaticsStatus::Singular) << r.reason;
  EXPECT_NE(r.reason.find("ill-conditioned"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("diagonal stiffness"), std::string::npos) << r.reason;
}

TEST_P(StaticsHonesty, HeldObjectWithoutGripsStillSaysNothingHoldsIt) {
  Scene scene = with_solver(test::two_arm_scene({12, 2, 2}));
  scene.grips.clear();
  GrippedObject object(scene);
  const ObjectState state =
      object.solve_from(object.reference_joints(), object.reference_positions());
  const StaticsResult& r = state.statics();
  EXPECT_EQ(r.status, StaticsStatus::Singular);
  EXPECT_NE(r.reason.find("nothing holds"), std::string::npos) << r.reason;
}

INSTANTIATE_TEST_SUITE_P(Each, StaticsHonesty, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

}  // namespace
}  // namespace shapectl
