#include <shapectl/robot/joints_file.hpp>

#include <shapectl/io/json_input.hpp>

namespace shapectl {

namespace {

bool has_boolean(const JsonInput& json, const char* key) {
  return json.has(key) && json.raw().at(key).is_boolean();
}

// The joint named `name` in `field`'s file: InputError when the robot has no such joint.
int named_joint(const JsonInput& field, const std::string& name, const RobotModel& robot) {
  const auto joint = robot.find_joint(name);
  if (!joint) field.fail_problem("unknown joint in " + robot.source());
  return *joint;
}

// Sets θ of the active joint `name` from `value`.
void set_active(const JsonInput& value, const std::string& name, const RobotModel& robot,
                Eigen::VectorXd& theta) {
  const int joint = named_joint(value, name, robot);
  const Joint& j = robot.joints()[static_cast<std::size_t>(joint)];
  if (j.mimic_master >= 0)
    value.fail_problem("mimics '" + robot.joints()[static_cast<std::size_t>(j.mimic_master)].name +
                       "'; give that joint's value instead");
  if (!j.movable()) value.fail_problem("a fixed joint has no value");
  if (robot.active_index(joint) < 0) value.fail_problem("not an active joint of the robot");
  theta[robot.active_index(joint)] = value.number();
}

// `run`'s result: {"joint_names": [..], "joints": [..]} in the same order.
void read_joint_arrays(const JsonInput& json, const RobotModel& robot, Eigen::VectorXd& theta) {
  const JsonInput names = json.at("joint_names"), values = json.at("joints");
  if (values.size() != names.size())
    values.fail("as many values as joint_names (" + std::to_string(names.size()) + ")");
  for (std::size_t k = 0; k < names.size(); ++k)
    set_active(values.at(k), names.at(k).string(), robot, theta);
}

// A result's "fixed_joints": the values its scene held the inactive joints at.
void read_fixed_joints(const JsonInput& fixed, const RobotModel& robot, Eigen::VectorXd& theta) {
  for (const auto& name : fixed.keys()) {
    const JsonInput value = fixed.at(name);
    const int joint = named_joint(value, name, robot);
    if (robot.active_index(joint) >= 0) {
      theta[robot.active_index(joint)] = value.number();
    } else if (value.number() != robot.fixed_value(joint)) {
      value.fail(nlohmann::json(robot.fixed_value(joint)).dump() +
                 ", the value this robot holds the joint at (the result was computed with "
                 "another)");
    }
  }
}

}  // namespace

Eigen::VectorXd read_joints(const JsonInput& json, const RobotModel& robot,
                            const Eigen::VectorXd& defaults) {
  // A result file of statics, solve (they say whether they converged) or run (whether it
  // settled) carries many other keys: only its joints are read. A hand-written file holds
  // nothing else, so a typo there is still an error.
  const bool run_result = json.is_object() && has_boolean(json, "settled");
  const bool result_file = json.is_object() && (has_boolean(json, "converged") || run_result);
  if (!result_file) json.expect_only({"joints"});
  Eigen::VectorXd theta = defaults;
  if (run_result && json.has("joint_names")) {
    read_joint_arrays(json, robot, theta);
  } else {
    const JsonInput joints = json.at("joints");
    for (const auto& name : joints.keys()) set_active(joints.at(name), name, robot, theta);
  }
  if (result_file && json.has("fixed_joints"))
    read_fixed_joints(json.at("fixed_joints"), robot, theta);
  return theta;
}

Eigen::VectorXd load_joints_file(const std::filesystem::path& file, const RobotModel& robot,
                                 const Eigen::VectorXd& defaults) {
  return read_joints(JsonInput::load(file), robot, defaults);
}

}  // namespace shapectl
