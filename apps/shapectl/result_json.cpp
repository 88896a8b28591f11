#include "result_json.hpp"

#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/kinematics.hpp>

namespace shapectl::cli {

nlohmann::json robot_json(const Scene& scene, const Eigen::VectorXd& joints) {
  const RobotModel& robot = *scene.robot->model;
  nlohmann::json out;
  const auto names = robot.active_joint_names();
  for (int j = 0; j < joints.size(); ++j) out["joints"][names[j]] = joints[j];
  const KinematicsState state = forward_kinematics(robot, joints);
  for (const auto& ee : scene.robot->end_effectors) {
    const Eigen::Isometry3d& T = state.T_world_link[ee.link];
    const Vec3 p = T * ee.tcp_link;
    nlohmann::json R = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) R.push_back({T.linear()(r, 0), T.linear()(r, 1), T.linear()(r, 2)});
    out["tools"][ee.name] = {{"position", {p.x(), p.y(), p.z()}}, {"rotation", R}};
  }
  return out;
}

Eigen::VectorXd read_joints_file(const std::string& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults) {
  const JsonInput root = JsonInput::load(file);
  root.expect_only({"joints"});
  const JsonInput joints = root.at("joints");
  Eigen::VectorXd theta = defaults;
  for (const auto& name : joints.keys()) {
    const auto joint = robot.find_joint(name);
    if (!joint || robot.active_index(*joint) < 0)
      joints.at(name).fail_problem("not an active joint of the robot");
    theta[robot.active_index(*joint)] = joints.at(name).number();
  }
  return theta;
}

}  // namespace shapectl::cli
