#pragma once
// Forward kinematics of a RobotModel's tree and geometric point Jacobians.
// Every pose and vector here is in the URDF root frame ("world"), metres and radians.
#include <Eigen/Geometry>
#include <vector>

#include <shapectl/robot/robot_model.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

// The robot at one configuration. Sized for one model; reuse it to avoid allocation.
struct KinematicsState {
  Eigen::VectorXd joints;                       // every joint's value (RobotModel::full_joints)
  std::vector<Eigen::Isometry3d> T_world_link;  // per link
  // Per joint: its axis and a point on it (the child frame origin), world frame.
  std::vector<Vec3> joint_axes_world;
  std::vector<Vec3> joint_origins_world;
};

// `active` holds θ (size model.active_count()); inactive joints take their fixed values.
KinematicsState forward_kinematics(const RobotModel& model, const Eigen::VectorXd& active);
// Same, reusing `state`'s storage: no heap allocation once the state has the model's sizes.
void forward_kinematics(const RobotModel& model, const Eigen::VectorXd& active,
                        KinematicsState& state);

// d(point)/dθ for a point fixed on `link`, given in the link frame: 3 × active_count.
Eigen::Matrix3Xd point_jacobian(const RobotModel& model, const KinematicsState& state, int link,
                                const Vec3& point_link);
// Same into `jacobian` (3 × active_count, overwritten), given the point in the world frame.
void point_jacobian_world(const RobotModel& model, const KinematicsState& state, int link,
                          const Vec3& point_world, Eigen::Ref<Eigen::Matrix3Xd> jacobian);
// gradient += Jᵀ·force for the point `point_world` on `link`, without forming J.
void add_point_jacobian_transpose(const RobotModel& model, const KinematicsState& state, int link,
                                  const Vec3& point_world, const Vec3& force,
                                  Eigen::Ref<Eigen::VectorXd> gradient);

}  // namespace shapectl
