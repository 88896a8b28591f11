#pragma once
// JOINTS.json: {"joints": {name: value}}, values of active joints (rad, or m for prismatic); or
// the result file of `statics` or `solve` (it has "converged") or `run` (it has "settled", and
// its joints as the arrays "joint_names" and "joints"), whose other keys are ignored except
// "fixed_joints": the values of the scene's inactive joints (gripper fingers) the result was
// computed with. Those set the joints that are active here (`kinematics` on the bare URDF, where
// every movable joint is), and must equal the robot's fixed values otherwise.
#include <Eigen/Core>
#include <filesystem>

#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

class JsonInput;

// θ with the named active joints set; the others keep `defaults` (size active_count()).
// Throws InputError naming the file and joint: not an active joint, not a finite number, a
// result's fixed joint at another value than the robot's.
Eigen::VectorXd read_joints(const JsonInput& json, const RobotModel& robot,
                            const Eigen::VectorXd& defaults);
Eigen::VectorXd load_joints_file(const std::filesystem::path& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults);

}  // namespace shapectl
