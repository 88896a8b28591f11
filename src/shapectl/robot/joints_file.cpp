#include <shapectl/robot/joints_file.hpp>

#include <shapectl/io/json_input.hpp>

namespace shapectl {

Eigen::VectorXd read_joints(const JsonInput& json, const RobotModel& robot,
                            const Eigen::VectorXd& defaults) {
  // A result file of statics, solve or run (it says whether it converged) carries many other
  // keys: only its joints are read. A hand-written file holds nothing else, so a typo there is
  // still an error.
  const bool result_file =
      json.is_object() && json.has("converged") && json.raw().at("converged").is_boolean();
  if (!result_file) json.expect_only({"joints"});
  const JsonInput joints = json.at("joints");
  Eigen::VectorXd theta = defaults;
  for (const auto& name : joints.keys()) {
    const auto joint = robot.find_joint(name);
    if (!joint || robot.active_index(*joint) < 0)
      joints.at(name).fail_problem("not an active joint of the robot");
    theta[robot.active_index(*joint)] = joints.at(name).number();
  }
  return theta;
}

Eigen::VectorXd load_joints_file(const std::filesystem::path& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults) {
  return read_joints(JsonInput::load(file), robot, defaults);
}

}  // namespace shapectl
