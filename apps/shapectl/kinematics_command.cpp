// shapectl kinematics ROBOT.urdf[.xacro] [--joints JOINTS.json|RESULT.json] [--spheres
// SPHERES.json] --out OUT.json Link poses at one configuration, and optionally self-collision
// clearances and limit checks.
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_output.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/robot/joints_file.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

#include "commands.hpp"
#include "output_option.hpp"
#include "result_json.hpp"
#include "robot_mesh_options.hpp"

namespace shapectl::cli {

namespace {

struct KinematicsOptions {
  std::string urdf;
  std::vector<std::string> package_paths;  // --package-path: the URDF's package:// meshes
  std::vector<std::string> xacro_args;     // --xacro-arg NAME:=VALUE
  std::string joints;
  std::string spheres;
  std::string out;
};

nlohmann::ordered_json collision_json(const RobotModel& robot, const CollisionModel& collision,
                                      const KinematicsState& state) {
  // A sphere is named by its link and its position in that link's list.
  std::vector<int> index_in_link(collision.spheres().size());
  std::map<int, int> seen;
  for (std::size_t s = 0; s < collision.spheres().size(); ++s)
    index_in_link[s] = seen[collision.spheres()[s].link]++;
  nlohmann::ordered_json closest = nlohmann::ordered_json::array();
  for (const auto& pair : collision.closest_pairs(state, 10)) {
    const auto a = static_cast<std::size_t>(pair.first);
    const auto b = static_cast<std::size_t>(pair.second);
    closest.push_back(
        {{"links",
          {robot.links()[static_cast<std::size_t>(collision.spheres()[a].link)].name,
           robot.links()[static_cast<std::size_t>(collision.spheres()[b].link)].name}},
         {"spheres", {index_in_link[a], index_in_link[b]}},
         {"clearance", pair.clearance}});
  }
  nlohmann::ordered_json out;
  // +inf when no sphere pair is checked: then there is no clearance to report.
  const double min_clearance = collision.min_clearance(state);
  if (min_clearance != std::numeric_limits<double>::infinity())
    out["min_clearance"] = min_clearance;
  out["margin"] = collision.margin();
  out["closest_pairs"] = closest;
  return out;
}

void run(const KinematicsOptions& options) {
  RobotModel robot = RobotModel::load_urdf_file(options.urdf, xacro_options(options.package_paths,
                                                                            options.xacro_args));
  print_robot_notes(robot, options.package_paths);
  // A joints file or a result of statics, solve or run (its fixed joints too); missing joints 0.
  Eigen::VectorXd active = Eigen::VectorXd::Zero(robot.active_count());
  if (!options.joints.empty()) active = load_joints_file(options.joints, robot, active);
  const KinematicsState state = forward_kinematics(robot, active);

  nlohmann::ordered_json out;
  nlohmann::ordered_json links = nlohmann::ordered_json::object();
  for (int link = 0; link < robot.link_count(); ++link) {
    const Eigen::Isometry3d& T = state.T_world_link[static_cast<std::size_t>(link)];
    links[robot.links()[static_cast<std::size_t>(link)].name] =
        result_pose_json(T.translation(), T.linear());
  }
  out["links"] = links;
  if (!options.spheres.empty()) {
    const CollisionModel collision = CollisionModel::load_json_file(robot, options.spheres);
    const nlohmann::ordered_json clearances = collision_json(robot, collision, state);
    for (const auto& [key, value] : clearances.items()) out[key] = value;
  }
  nlohmann::ordered_json violations = nlohmann::ordered_json::array();
  for (const auto& v : limit_violations(robot, state.joints))
    violations.push_back(
        {{"joint", v.joint}, {"value", v.value}, {"lower", v.lower}, {"upper", v.upper}});
  out["limit_violations"] = violations;

  require_finite(out, "kinematics", "");
  write_json_file(options.out, out);
}

}  // namespace

void add_kinematics_command(CLI::App& app) {
  auto options = std::make_shared<KinematicsOptions>();
  CLI::App* command = app.add_subcommand(
      "kinematics", "Link poses of a URDF robot at given joint values; clearances with --spheres");
  command->add_option("robot", options->urdf, "Robot description (URDF, or URDF xacro)")
      ->required();
  command->add_option("--joints", options->joints,
                      "JOINTS.json {\"joints\": {\"name\": radians}}, or a result of statics, "
                      "solve or run; missing joints are 0");
  command->add_option("--spheres", options->spheres, "Collision spheres JSON (see docs/robot.md)");
  command->add_option("--out", options->out, "Output JSON: link poses in the URDF root frame")
      ->required()
      ->check(writable_output());
  add_package_path_option(*command, options->package_paths);
  add_xacro_arg_option(*command, options->xacro_args);
  command->callback([options] { run(*options); });
}

}  // namespace shapectl::cli
