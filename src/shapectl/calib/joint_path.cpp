#include <shapectl/calib/joint_path.hpp>

#include <cmath>
#include <stdexcept>

namespace shapectl {

ObjectState equilibrium_along_path(const GrippedObject& object, const Eigen::VectorXd& joints,
                                   double max_step) {
  const Eigen::VectorXd& start = object.reference_joints();
  const int steps = std::max(1, int(std::ceil((joints - start).cwiseAbs().maxCoeff() / max_step)));
  Positions x = object.reference_positions();
  Eigen::VectorXd at = start;
  for (int s = 1;; ++s) {
    const Eigen::VectorXd to = start + (joints - start) * (double(s) / steps);
    Positions carried = x;
    object.carry_gripped_nodes(at, to, x, carried);
    ObjectState state = object.solve_from(to, carried);
    if (!state.statics().converged())
      throw std::runtime_error("no equilibrium on the way from the reference joints (step " +
                               std::to_string(s) + " of " + std::to_string(steps) + ": " +
                               state.statics().reason + ")");
    if (s == steps) return state;
    x = state.positions();
    at = to;
  }
}

}  // namespace shapectl
