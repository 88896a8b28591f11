#include <shapectl/sim/grip_springs.hpp>

namespace shapectl {

GripSprings::GripSprings(const RobotModel& robot, std::vector<GrippedNode> nodes, double stiffness)
    : robot_(robot), nodes_(std::move(nodes)), stiffness_(stiffness), anchors_(nodes_.size()) {}

std::vector<GrippedNode> GripSprings::attach(const KinematicsState& reference_state,
                                             const Positions& reference_positions,
                                             const std::vector<std::pair<int, int>>& node_link) {
  std::vector<GrippedNode> out;
  for (const auto& [node, link] : node_link)
    out.push_back({node, link,
                   reference_state.T_world_link[link].inverse() * reference_positions.segment<3>(3 * node)});
  return out;
}

void GripSprings::set_robot_state(const KinematicsState& state) {
  state_ = state;
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    anchors_[k] = state_.T_world_link[nodes_[k].link] * nodes_[k].point_link;
}

std::vector<Vec3> GripSprings::anchors() const { return anchors_; }

double GripSprings::value(const Positions& x) const {
  double e = 0;
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    e += (x.segment<3>(3 * nodes_[k].node) - anchors_[k]).squaredNorm();
  return 0.5 * stiffness_ * e;
}

void GripSprings::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    const int i = nodes_[k].node;
    gradient.segment<3>(3 * i) += stiffness_ * (x.segment<3>(3 * i) - anchors_[k]);
  }
}

void GripSprings::add_hessian(const Positions&, Triplets& hessian, bool) const {
  for (const auto& g : nodes_)
    for (int d = 0; d < 3; ++d) hessian.emplace_back(3 * g.node + d, 3 * g.node + d, stiffness_);
}

Eigen::MatrixXd GripSprings::force_jacobian(int node_count) const {
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(3 * node_count, robot_.active_count());
  Eigen::Matrix3Xd J(3, robot_.active_count());
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    point_jacobian_world(robot_, state_, nodes_[k].link, anchors_[k], J);
    dF.middleRows<3>(3 * nodes_[k].node) += stiffness_ * J;
  }
  return dF;
}

Eigen::VectorXd GripSprings::force_jacobian_transpose_times(const Eigen::VectorXd& lambda) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(robot_.active_count());
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    add_point_jacobian_transpose(robot_, state_, nodes_[k].link, anchors_[k],
                                 stiffness_ * lambda.segment<3>(3 * nodes_[k].node), out);
  return out;
}

}  // namespace shapectl
