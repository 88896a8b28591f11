// The simulated world where its object has no equilibrium: a failed solve (NoEquilibrium, which
// `run --world` reports with exit 2), never a bug; the world stays where it was.
#include <shapectl/calib/simulated_world.hpp>

#include <gtest/gtest.h>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

TEST(SimulatedWorld, JointsWithoutAnEquilibriumThrowNoEquilibriumAndKeepTheWorld) {
  const Scene model = load_scene(test::source_path("scenes/yumi_bar.json"));
  Scene world = model;
  world.statics.max_iterations = 3;  // from rest it needs 2; the walk below, more
  SimulatedWorld simulated(world, model, SimulatedCamera{}, 10);
  const Positions before = simulated.positions();
  // Both shoulders turned in by 0.5 rad: the grips crush the bar.
  Eigen::VectorXd crushing = model.robot->reference_joints;
  crushing[0] -= 0.5, crushing[7] += 0.5;
  EXPECT_THROW(simulated.step(0, crushing), NoEquilibrium);
  EXPECT_EQ(simulated.positions(), before);
  // Where it has one, the world settles there.
  Eigen::VectorXd near = model.robot->reference_joints;
  near[0] -= 1e-3;
  EXPECT_NO_THROW(simulated.step(1, near));
  EXPECT_NE(simulated.positions(), before);
}

}  // namespace
}  // namespace shapectl
