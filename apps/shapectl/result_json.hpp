#pragma once
// JSON pieces shared by the commands' result files.
#include <nlohmann/json.hpp>
#include <string>

#include <shapectl/sim/scene.hpp>

namespace shapectl::cli {

// {"joints": {name: rad}, "tools": {ee name: {"position": [..], "rotation": [[..]..]}}}
nlohmann::json robot_json(const Scene& scene, const Eigen::VectorXd& joints);
// θ from JOINTS.json {"joints": {name: rad}}; joints not named keep `defaults`.
Eigen::VectorXd read_joints_file(const std::string& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults);

}  // namespace shapectl::cli
