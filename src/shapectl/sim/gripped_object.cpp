#include <shapectl/sim/gripped_object.hpp>

#include <stdexcept>

namespace shapectl {

namespace {
std::vector<std::pair<int, int>> node_links(const Scene& scene) {
  std::vector<std::pair<int, int>> out;
  for (const auto& g : scene.grips)
    for (int node : g.nodes) out.emplace_back(node, scene.robot->end_effectors[g.end_effector].link);
  return out;
}
}  // namespace

GrippedObject::GrippedObject(const Scene& scene) : scene_(scene) {
  if (!scene_.robot) throw std::invalid_argument("GrippedObject needs a scene with a robot");
  const auto pairs = node_links(scene_);
  const KinematicsState reference = forward_kinematics(robot(), scene_.robot->reference_joints);
  grips_ = std::make_unique<GripSprings>(
      robot(), GripSprings::attach(reference, scene_.world_rest_positions(), pairs), scene_.grip_stiffness);
  grips_->set_robot_state(reference);
  std::vector<int> held;
  for (const auto& p : pairs) held.push_back(p.first);
  statics_ = std::make_unique<ObjectStatics>(scene_, std::vector<const EnergyTerm*>{grips_.get()}, held);
}

StaticsResult GrippedObject::solve(const Eigen::VectorXd& joints, Positions& x, int max_iterations) {
  grips_->set_robot_state(forward_kinematics(robot(), joints));
  return statics_->solve(x, max_iterations);
}

void GrippedObject::carry_gripped_nodes(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                        const Positions& at_from, Positions& x) const {
  const KinematicsState a = forward_kinematics(robot(), from), b = forward_kinematics(robot(), to);
  for (const auto& g : scene_.grips) {
    const int link = scene_.robot->end_effectors[g.end_effector].link;
    const Eigen::Isometry3d motion = b.T_world_link[link] * a.T_world_link[link].inverse();
    for (int i : g.nodes) x.segment<3>(3 * i) = motion * at_from.segment<3>(3 * i);
  }
}

Eigen::MatrixXd GrippedObject::sensitivity(const Positions& x) {
  return statics_->solver().solve_hessian(x, grips_->force_jacobian(node_count()));
}

Eigen::VectorXd GrippedObject::adjoint(const Positions& x, const Eigen::VectorXd& v) {
  const Eigen::VectorXd lambda = statics_->solver().solve_hessian(x, v);
  return grips_->force_jacobian_transpose_times(lambda);
}

}  // namespace shapectl
