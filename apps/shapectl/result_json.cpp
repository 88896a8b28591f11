#include "result_json.hpp"

#include <cmath>
#include <iostream>
#include <limits>

#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/scene_checks.hpp>

#include "robot_mesh_options.hpp"

namespace shapectl::cli {

nlohmann::json robot_json(const Scene& scene, const Eigen::VectorXd& joints) {
  const RobotModel& robot = *scene.robot->model;
  nlohmann::json out;
  const auto names = robot.active_joint_names();
  for (int j = 0; j < joints.size(); ++j) out["joints"][names[j]] = joints[j];
  out["fixed_joints"] = fixed_joints_json(robot);
  const KinematicsState state = forward_kinematics(robot, joints);
  for (const auto& ee : scene.robot->end_effectors) {
    const Eigen::Isometry3d& T = state.T_world_link[ee.link];
    out["tools"][ee.name] = result_pose_json(T * ee.tcp_link, T.linear());
  }
  return out;
}

nlohmann::json fixed_joints_json(const RobotModel& robot) {
  nlohmann::json out = nlohmann::json::object();
  for (int j = 0; j < robot.joint_count(); ++j) {
    const Joint& joint = robot.joints()[static_cast<std::size_t>(j)];
    if (joint.movable() && joint.mimic_master < 0 && robot.active_index(j) < 0)
      out[joint.name] = robot.fixed_value(j);
  }
  return out;
}

nlohmann::json contacts_json(const ObstacleContact* contact, const SelfContact* self,
                             const Positions& x) {
  if (!contact && !self) return nullptr;
  ContactSummary summary;
  summary.min_distance = std::numeric_limits<double>::infinity();
  if (contact) summary = contact->summary(x);
  nlohmann::json out = {{"count", summary.count}, {"force_total", vec3_json(summary.force_total)}};
  // +inf when no pair is that close: JSON has no infinity, so the key is left out.
  if (std::isfinite(summary.min_distance)) out["min_distance"] = summary.min_distance;
  nlohmann::json by_obstacle = nlohmann::json::object();
  for (std::size_t k = 0; k < summary.by_obstacle.size(); ++k)
    by_obstacle[contact->obstacles()[k].name] = {{"count", summary.by_obstacle[k].count},
                                                 {"force",
                                                  vec3_json(summary.by_obstacle[k].force)}};
  out["by_obstacle"] = by_obstacle;
  if (self) {
    const SelfContactSummary s = self->summary(x);
    out["self"] = {{"count", s.count}};
    if (std::isfinite(s.min_distance)) out["self"]["min_distance"] = s.min_distance;
  }
  if (contact) out["stiffness"] = summary.stiffness;
  return out;
}

void add_tolerance_option(CLI::App& command, double& tolerance) {
  command
      .add_option("--tolerance", tolerance,
                  "M: the largest target error (m) that counts as reached; above it the status "
                  "is best effort, with the reasons")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

void print_scene_notes(const Scene& scene, const std::vector<std::string>& package_paths) {
  if (scene.robot) print_robot_notes(*scene.robot->model, package_paths);
  for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";
  if (scene.robot)
    for (const auto& line : describe_grips(scene)) std::cerr << line << "\n";
}

namespace {
template <class Json>
void require_finite_numbers(const Json& result, const std::string& what,
                            const std::string& context) {
  if (const auto where = first_non_finite(result))
    throw SolverFailure(what + ": " + (where->empty() ? "the result" : *where) + " is not finite" +
                        (context.empty() ? "" : " (" + context + ")") + "; nothing written");
}
}  // namespace

void require_finite(const nlohmann::json& result, const std::string& what,
                    const std::string& context) {
  require_finite_numbers(result, what, context);
}
void require_finite(const nlohmann::ordered_json& result, const std::string& what,
                    const std::string& context) {
  require_finite_numbers(result, what, context);
}

}  // namespace shapectl::cli
