#pragma once
// Grip energy (paper eq. 5): each gripped node i of end effector e is tied by a spring of
// stiffness K to the point T_e(θ) qᵢ, qᵢ being the node's reference position expressed in
// the end effector's link frame at the reference joints θ⁰:
//   E_grip = K/2 Σ |xᵢ − T_e(θ) qᵢ|²,   F = −∂E/∂x,   ∂fᵢ/∂θ = K ∂(T_e(θ) qᵢ)/∂θ (eq. 10).
// GripSprings is the fixed description (which node, which link, qᵢ, K); GripEnergy is the
// energy term at one robot configuration (its anchors T_e(θ) qᵢ).
#include <vector>

#include <shapectl/fem/energy_term.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {

struct GrippedNode {
  int node = -1;
  int link = -1;    // the end effector's link
  Vec3 point_link;  // qᵢ, link frame, metres
};

class GripSprings {
 public:
  // nodes: gripped node → link, with qᵢ (see attach). stiffness K in N/m. The robot must
  // outlive this.
  GripSprings(const RobotModel& robot, std::vector<GrippedNode> nodes, double stiffness);
  // qᵢ of each (node, link) from `reference_positions` (world, 3n) and the link poses in
  // `reference_state` (θ⁰).
  static std::vector<GrippedNode> attach(const KinematicsState& reference_state,
                                         const Positions& reference_positions,
                                         const std::vector<std::pair<int, int>>& node_link);

  // The spring anchors T_e(θ) qᵢ (world) with the robot at `state`, in nodes() order.
  std::vector<Vec3> anchors(const KinematicsState& state) const;
  // ∂F/∂θ at `state`, 3n × active_count (rows of non-gripped nodes are zero).
  Eigen::MatrixXd force_jacobian(const KinematicsState& state, int node_count) const;
  // λᵀ ∂F/∂θ at `state` without forming ∂F/∂θ (adjoint method): Σᵢ K J_iᵀ λᵢ.
  Eigen::VectorXd force_jacobian_transpose_times(const KinematicsState& state,
                                                 const Eigen::VectorXd& lambda) const;

  const std::vector<GrippedNode>& nodes() const { return nodes_; }
  double stiffness() const { return stiffness_; }

 private:
  const RobotModel& robot_;
  std::vector<GrippedNode> nodes_;
  double stiffness_;
};

// The grip energy with the springs anchored at one robot configuration.
class GripEnergy : public EnergyTerm {
 public:
  GripEnergy(const GripSprings& springs, const KinematicsState& state);

  std::string_view name() const override { return "grip"; }
  double value(const Positions& x) const override;
  void add_gradient(const Positions& x, Eigen::VectorXd& gradient) const override;
  // One element per gripped node: K·I₃.
  void hessian_elements(const Positions& x, ElementNodes& elements) const override;
  void add_hessian(const Positions& x, ElementHessianSink& sink, bool project_psd) const override;
  const std::vector<Vec3>& anchors() const { return anchors_; }

 private:
  const GripSprings* springs_;
  std::vector<Vec3> anchors_;
};

}  // namespace shapectl
