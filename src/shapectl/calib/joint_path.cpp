#include <shapectl/calib/joint_path.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace shapectl {

namespace {
// Solves at `to` from the equilibrium `from` (at its joints), halving the step where Newton
// does not converge: far from θ⁰ a step that is small in every joint can still cross a
// region where the warm start is poor. Throws with Newton's reason after `depth` halvings.
ObjectState step_to(const GrippedObject& object, const ObjectState& from, const Eigen::VectorXd& to,
                    int depth, const StopRequest& stop) {
  Positions carried = from.positions();
  object.carry_gripped_nodes(from.joints(), to, from.positions(), carried);
  ObjectState state =
      object.solve_along(from.joints(), to, carried, 0, nullptr, stop, from.workspaces());
  if (state.statics().converged() || depth == 0 || (stop && stop())) return state;
  ObjectState halfway = step_to(object, from, (from.joints() + to) / 2, depth - 1, stop);
  if (!halfway.statics().converged()) return halfway;
  return step_to(object, halfway, to, depth - 1, stop);
}
}  // namespace

ObjectState equilibrium_along_path(const GrippedObject& object, const Eigen::VectorXd& joints,
                                   double max_step, const StopRequest& stop,
                                   std::shared_ptr<WorkspacePool> workspaces) {
  const Eigen::VectorXd& start = object.reference_joints();
  const double distance = (joints - start).cwiseAbs().maxCoeff();
  // Compared before rounding: a huge or non-finite distance must not overflow the count.
  if (!(distance <= max_step * max_joint_path_steps))
    throw NoEquilibrium("the joints are " + std::to_string(distance) +
                        " rad from the reference joints, more than " +
                        std::to_string(max_joint_path_steps) + " steps of " +
                        std::to_string(max_step) + " rad");
  const int steps = std::max(1, int(std::ceil(distance / max_step)));
  // The rest shape at θ⁰, unsolved: the first step solves from it. The steps share a pool.
  if (!workspaces) workspaces = WorkspacePool::create();
  ObjectState state = object.make_state(start, object.reference_positions(), std::move(workspaces));
  for (int s = 1; s <= steps; ++s) {
    state = step_to(object, state, start + (joints - start) * (double(s) / steps), 4, stop);
    if (!state.statics().converged()) break;
  }
  if (!state.statics().converged())
    throw NoEquilibrium("no equilibrium on the way from the reference joints (" +
                        state.statics().reason + ")");
  return state;
}

}  // namespace shapectl
