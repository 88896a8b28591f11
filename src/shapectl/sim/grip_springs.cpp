#include <shapectl/sim/grip_springs.hpp>

namespace shapectl {

GripSprings::GripSprings(const RobotModel& robot, std::vector<GrippedNode> nodes, double stiffness)
    : robot_(robot), nodes_(std::move(nodes)), stiffness_(stiffness) {}

std::vector<GrippedNode> GripSprings::attach(const KinematicsState& reference_state,
                                             const Positions& reference_positions,
                                             const std::vector<std::pair<int, int>>& node_link) {
  std::vector<GrippedNode> out;
  for (const auto& [node, link] : node_link)
    out.push_back(
        {node, link,
         reference_state.T_world_link[link].inverse() * reference_positions.segment<3>(3 * node)});
  return out;
}

std::vector<Vec3> GripSprings::anchors(const KinematicsState& state) const {
  std::vector<Vec3> out(nodes_.size());
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    out[k] = state.T_world_link[nodes_[k].link] * nodes_[k].point_link;
  return out;
}

Eigen::MatrixXd GripSprings::force_jacobian(const KinematicsState& state, int node_count) const {
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(3 * node_count, robot_.active_count());
  Eigen::Matrix3Xd J(3, robot_.active_count());
  const std::vector<Vec3> anchor = anchors(state);
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    point_jacobian_world(robot_, state, nodes_[k].link, anchor[k], J);
    dF.middleRows<3>(3 * nodes_[k].node) += stiffness_ * J;
  }
  return dF;
}

Eigen::VectorXd GripSprings::force_jacobian_transpose_times(const KinematicsState& state,
                                                            const Eigen::VectorXd& lambda) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(robot_.active_count());
  const std::vector<Vec3> anchor = anchors(state);
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    add_point_jacobian_transpose(robot_, state, nodes_[k].link, anchor[k],
                                 stiffness_ * lambda.segment<3>(3 * nodes_[k].node), out);
  return out;
}

GripEnergy::GripEnergy(const GripSprings& springs, const KinematicsState& state)
    : springs_(&springs), anchors_(springs.anchors(state)) {}

double GripEnergy::value(const Positions& x) const {
  double e = 0;
  const auto& nodes = springs_->nodes();
  for (std::size_t k = 0; k < nodes.size(); ++k)
    e += (x.segment<3>(3 * nodes[k].node) - anchors_[k]).squaredNorm();
  return 0.5 * springs_->stiffness() * e;
}

void GripEnergy::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const auto& nodes = springs_->nodes();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const int i = nodes[k].node;
    gradient.segment<3>(3 * i) += springs_->stiffness() * (x.segment<3>(3 * i) - anchors_[k]);
  }
}

void GripEnergy::hessian_elements(const Positions&, ElementNodes& elements) const {
  for (const auto& g : springs_->nodes()) elements.add({g.node});
}

void GripEnergy::add_hessian(const Positions&, ElementHessianSink& sink, bool) const {
  const double k = springs_->stiffness();
  sink.add_blocks(
      [k](std::size_t, double* block) { Eigen::Map<Mat3>{block} = k * Mat3::Identity(); });
}

}  // namespace shapectl
