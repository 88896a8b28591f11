#pragma once
// JOINTS.json: {"joints": {name: value}}, values of active joints (rad, or m for prismatic); or
// the result file of `statics`, `solve` or `run` (it has "converged"), whose other keys are
// ignored.
#include <Eigen/Core>
#include <filesystem>

#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

class JsonInput;

// θ with the named active joints set; the others keep `defaults` (size active_count()).
// Throws InputError naming the file and joint: not an active joint, not a finite number.
Eigen::VectorXd read_joints(const JsonInput& json, const RobotModel& robot,
                            const Eigen::VectorXd& defaults);
Eigen::VectorXd load_joints_file(const std::filesystem::path& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults);

}  // namespace shapectl
