#include <shapectl/calib/simulated_world.hpp>

#include <cmath>
#include <stdexcept>

#include <shapectl/calib/joint_path.hpp>

namespace shapectl {

SimulatedWorld::SimulatedWorld(const Scene& world, const Scene& model, SimulatedCamera camera,
                               double rate, unsigned seed)
    : object_(world), camera_(std::move(camera)), period_(1 / rate), rng_(seed) {
  if (!model.robot || world.object_mesh->node_count() != model.object_mesh->node_count() ||
      world.object_mesh->tet_count() != model.object_mesh->tet_count())
    throw std::invalid_argument(
        "the world's object must have the model's mesh (same nodes and tetrahedra)");
  if (world.robot->model->active_joint_names() != model.robot->model->active_joint_names())
    throw std::invalid_argument("the world's robot must have the model's active joints");
  if (!(rate > 0 && std::isfinite(rate)))
    throw std::invalid_argument("the camera rate must be positive");
  state_.emplace(
      equilibrium_along_path(object_, object_.reference_joints(), 0.05, {}, workspaces_));
}

std::optional<ObservationFrame> SimulatedWorld::step(double time,
                                                     const Eigen::VectorXd& measured_joints) {
  // A robot standing still leaves the world as it is: no solve (it shares the cores with the
  // controller it is testing).
  if (measured_joints != state_->joints()) {
    // From the last shape with the gripped nodes carried along, as the real object moves: from
    // the last shape alone Newton first pulls the grips across, which can take it past its cap.
    Positions x = state_->positions();
    object_.carry_gripped_nodes(state_->joints(), measured_joints, state_->positions(), x);
    ObjectState next =
        object_.solve_along(state_->joints(), measured_joints, x, 0, nullptr, {}, workspaces_);
    if (!next.statics().converged())
      next = equilibrium_along_path(object_, measured_joints, 0.05, {}, workspaces_);
    state_.emplace(std::move(next));
  }
  if (time < next_time_) return std::nullopt;
  next_time_ = std::max(next_time_ + period_, time);
  ObservationFrame frame =
      camera_.observe(object_.mesh(), state_->positions(), measured_joints, rng_);
  frame.time = time;
  return frame;
}

double SimulatedWorld::true_error(const ShapeTargets& targets) const {
  if (targets.empty()) return NAN;
  double sum = 0;
  for (int k = 0; k < targets.size(); ++k)
    sum += (state_->positions().segment<3>(3 * targets.nodes[k]) - targets.positions[k]).norm();
  return sum / targets.size();
}

}  // namespace shapectl
