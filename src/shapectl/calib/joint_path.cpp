#include <shapectl/calib/joint_path.hpp>

#include <cmath>

namespace shapectl {

namespace {
// Solves at `to` from the equilibrium `from` (at its joints), halving the step where Newton
// does not converge: far from θ⁰ a step that is small in every joint can still cross a
// region where the warm start is poor. Throws with Newton's reason after `depth` halvings.
ObjectState step_to(const GrippedObject& object, const ObjectState& from, const Eigen::VectorXd& to,
                    int depth) {
  Positions carried = from.positions();
  object.carry_gripped_nodes(from.joints(), to, from.positions(), carried);
  ObjectState state = object.solve_from(to, carried);
  if (state.statics().converged() || depth == 0) return state;
  ObjectState halfway = step_to(object, from, (from.joints() + to) / 2, depth - 1);
  if (!halfway.statics().converged()) return halfway;
  return step_to(object, halfway, to, depth - 1);
}
}  // namespace

ObjectState equilibrium_along_path(const GrippedObject& object, const Eigen::VectorXd& joints,
                                   double max_step) {
  const Eigen::VectorXd& start = object.reference_joints();
  const int steps = std::max(1, int(std::ceil((joints - start).cwiseAbs().maxCoeff() / max_step)));
  // The rest shape at θ⁰, unsolved: the first step solves from it.
  ObjectState state = object.make_state(start, object.reference_positions());
  for (int s = 1; s <= steps; ++s) {
    state = step_to(object, state, start + (joints - start) * (double(s) / steps), 4);
    if (!state.statics().converged()) break;
  }
  if (!state.statics().converged())
    throw NoEquilibrium("no equilibrium on the way from the reference joints (" +
                        state.statics().reason + ")");
  return state;
}

}  // namespace shapectl
