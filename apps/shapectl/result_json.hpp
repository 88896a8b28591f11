#pragma once
// JSON pieces shared by the commands' result files.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/contact/self_contact.hpp>
#include <shapectl/sim/scene.hpp>

#include "commands.hpp"

namespace shapectl::cli {

// {"joints": {name: rad}, "fixed_joints": {name: value}, "tools": {ee name: {"position": [..],
// "rotation": [[..]..]}}}
nlohmann::json robot_json(const Scene& scene, const Eigen::VectorXd& joints);
// {name: value} of the robot's inactive movable joints (not mimics: gripper fingers): a result
// carries them, so that `--joints RESULT` gives its pose on the bare URDF too (kinematics).
nlohmann::json fixed_joints_json(const RobotModel& robot);
// The contacts at positions x: {"count", "min_distance" (m; left out when no pair is within
// the contact distance), "force_total": [..] (N, the obstacles' force on the object),
// "by_obstacle": {name: {"count", "force"}}} with the obstacles (else count 0, no force, no
// obstacle), and "self": {"count", "min_distance"} with self-contact (its pairs are in neither
// count nor force_total: internal forces sum to zero). Null with neither.
nlohmann::json contacts_json(const ObstacleContact* contact, const SelfContact* self,
                             const Positions& x);
// --tolerance M: the target error (m) under which a result counts as reached (default 1 mm).
void add_tolerance_option(CLI::App& command, double& tolerance);
// Throws SolverFailure ("<what>: <field> is not finite (<context>)") if any number in `result` is
// NaN or infinite: JSON would write it as null, and a result is never written with one.
void require_finite(const nlohmann::json& result, const std::string& what,
                    const std::string& context);
void require_finite(const nlohmann::ordered_json& result, const std::string& what,
                    const std::string& context);
// The robot's notes (robot_mesh_options.hpp: skipped geometry, visual meshes not found through
// `package_paths`), the scene's warnings ("warning: <file>: <field>: ...") and the nodes each
// grip caught, one line each, on stderr: the traps a user must see before trusting a result.
void print_scene_notes(const Scene& scene, const std::vector<std::string>& package_paths);

}  // namespace shapectl::cli
