#pragma once
// The equilibrium at joints far from where the object is known: walk θ from the reference
// joints in steps of at most `max_step` (rad, largest joint), carrying the gripped nodes along
// with their grippers and solving at each step. One jump would drag the gripped nodes past
// their neighbours and invert elements.
#include <stdexcept>

#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

// Steps a path may take: 50 rad at the default step, beyond any joint range a robot has
// (a continuous joint's reading far off would otherwise make the walk last hours).
inline constexpr int max_joint_path_steps = 1000;

// The object has no equilibrium found on the way: a failed solve (a material too soft for
// its weight, a pose that inverts it, joints too far to walk to), not a bug.
class NoEquilibrium : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A step where Newton does not converge is halved (up to 4 times). Throws NoEquilibrium with
// Newton's reason when an equilibrium on the way is not found even so, or when the path needs
// more than max_joint_path_steps steps. `stop` (may be empty) ends Newton early: the walk then
// throws with Newton's "stopped" reason. The states on the way take their workspaces from
// `workspaces` (null: a pool of the walk's own).
ObjectState equilibrium_along_path(const GrippedObject& object, const Eigen::VectorXd& joints,
                                   double max_step = 0.05, const StopRequest& stop = {},
                                   std::shared_ptr<WorkspacePool> workspaces = nullptr);

}  // namespace shapectl
