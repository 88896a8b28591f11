#pragma once
// ∂F/∂θ of the contact with obstacles on robot links (F = −∂E/∂x). Each obstacle point p moves
// rigidly with its link, ∂p/∂θ its point Jacobian, so ∂F/∂θ = −Σ ∂²E/∂x∂p · ∂p/∂θ
// (ObstacleContact::for_each_coupling gives the blocks ∂²E/∂x∂p). Obstacles fixed in the world
// add nothing.
#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl {

// 3n × active_count at x; `contact` posed at `state` (ObstacleContact::posed).
Eigen::MatrixXd contact_force_jacobian(const ObstacleContact& contact, const RobotModel& robot,
                                       const KinematicsState& state, const Positions& x);
// λᵀ ∂F/∂θ without forming ∂F/∂θ (the adjoint method), added to `out` (size active_count).
void add_contact_force_jacobian_transpose_times(const ObstacleContact& contact,
                                                const RobotModel& robot,
                                                const KinematicsState& state, const Positions& x,
                                                const Eigen::VectorXd& lambda,
                                                Eigen::VectorXd& out);

}  // namespace shapectl
