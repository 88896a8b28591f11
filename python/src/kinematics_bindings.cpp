// shapectl.kinematics: what `shapectl kinematics` reports (link poses, clearance, the closest
// sphere pairs, joint-limit violations), for a URDF robot or a scene's robot.
#include <limits>
#include <optional>

#include <shapectl/robot/kinematics.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

struct SpherePair {
  std::pair<std::string, std::string> links;
  std::pair<int, int> spheres;  // index of each sphere within its link's list
  double clearance = 0;
};

struct Kinematics {
  Eigen::VectorXd joints;
  std::vector<std::string> joint_names;
  std::map<std::string, Pose> links;
  std::map<std::string, Pose> tools;  // a scene's end effectors only
  std::optional<double> min_clearance;
  std::optional<double> margin;
  std::vector<SpherePair> closest_pairs;
  std::vector<LimitViolation> limit_violations;
};

void add_clearances(const RobotModel& robot, const CollisionModel& collision,
                    const KinematicsState& state, Kinematics& out) {
  const auto& spheres = collision.spheres();
  std::vector<int> index_in_link(spheres.size());
  std::map<int, int> seen;
  for (std::size_t s = 0; s < spheres.size(); ++s) index_in_link[s] = seen[spheres[s].link]++;
  const auto link_name = [&](int sphere) {
    return robot.links()[static_cast<std::size_t>(spheres[static_cast<std::size_t>(sphere)].link)]
        .name;
  };
  for (const auto& pair : collision.closest_pairs(state, 10))
    out.closest_pairs.push_back({{link_name(pair.first), link_name(pair.second)},
                                 {index_in_link[static_cast<std::size_t>(pair.first)],
                                  index_in_link[static_cast<std::size_t>(pair.second)]},
                                 pair.clearance});
  // +inf when no sphere pair is checked: no clearance to report.
  const double clearance = collision.min_clearance(state);
  if (clearance != std::numeric_limits<double>::infinity()) out.min_clearance = clearance;
  out.margin = collision.margin();
}

Kinematics compute(const RobotModel& robot, const CollisionModel* collision,
                   const Eigen::VectorXd& joints) {
  Kinematics out;
  out.joints = joints;
  out.joint_names = robot.active_joint_names();
  const KinematicsState state = forward_kinematics(robot, joints);
  for (int link = 0; link < robot.link_count(); ++link) {
    const Eigen::Isometry3d& T = state.T_world_link[static_cast<std::size_t>(link)];
    out.links[robot.links()[static_cast<std::size_t>(link)].name] = {T.translation(), T.linear()};
  }
  if (collision) add_clearances(robot, *collision, state, out);
  out.limit_violations = limit_violations(robot, state.joints);
  return out;
}

Kinematics robot_kinematics(const RobotHandle& r, const py::object& joints_in,
                            const py::object& spheres) {
  const RobotModel& robot = *r.model;
  // As the CLI: joints not named are 0.
  const Eigen::VectorXd joints =
      joints_from(joints_in, robot, Eigen::VectorXd::Zero(robot.active_count()));
  std::optional<std::filesystem::path> spheres_path;
  if (!spheres.is_none())
    spheres_path = path_from(spheres, "spheres", "a collision spheres JSON path");
  py::gil_scoped_release release;
  std::optional<CollisionModel> loaded;
  if (spheres_path) loaded = CollisionModel::load_json_file(robot, *spheres_path);
  const CollisionModel* collision = loaded ? &*loaded : r.collisions.get();
  return compute(robot, collision, joints);
}

Kinematics scene_kinematics(const SceneHandle& s, const py::object& joints_in) {
  if (!s.scene->robot) throw InputError(s.scene->source.string(), "robot", "a robot (missing key)");
  const RobotSetup& setup = *s.scene->robot;
  const Eigen::VectorXd joints = joints_from(joints_in, *setup.model, setup.reference_joints);
  py::gil_scoped_release release;
  Kinematics out = compute(*setup.model, setup.collisions.get(), joints);
  out.tools = tool_poses(*s.scene, joints);
  return out;
}

}  // namespace

void bind_kinematics(py::module_& m) {
  py::class_<SpherePair>(m, "SpherePair", "One of the closest collision sphere pairs.")
      .def_readonly("links", &SpherePair::links, "The two spheres' links.")
      .def_readonly("spheres", &SpherePair::spheres, "Each sphere's index in its link's list.")
      .def_readonly("clearance", &SpherePair::clearance,
                    "Distance between the surfaces, m (negative: overlap).");

  py::class_<Kinematics>(m, "Kinematics",
                         "The robot at one configuration, the fields of `shapectl kinematics`.")
      .def_readonly("joints", &Kinematics::joints, "θ: array of shape (m,).")
      .def_readonly("joint_names", &Kinematics::joint_names, "Names of θ's entries.")
      .def_readonly("links", &Kinematics::links, "Every link's pose: {name: Pose}.")
      .def_readonly("tools", &Kinematics::tools,
                    "Tool pose of each end effector (scenes only): {name: Pose}.")
      .def_readonly("min_clearance", &Kinematics::min_clearance,
                    "Smallest sphere-pair clearance, m; None without spheres or pairs.")
      .def_readonly("margin", &Kinematics::margin,
                    "The spheres' barrier margin, m; None without spheres.")
      .def_readonly("closest_pairs", &Kinematics::closest_pairs,
                    "The 10 closest sphere pairs, closest first.")
      .def_readonly("limit_violations", &Kinematics::limit_violations,
                    "Joints outside their hard limits.");

  m.def(
      "kinematics", &robot_kinematics, py::arg("robot"), py::arg("joints") = py::none(),
      py::arg("spheres") = py::none(),
      "Forward kinematics of a Robot at `joints` (None: all 0; a {name: rad} dict, others 0; or an "
      "(m,) array), as `shapectl kinematics ROBOT.urdf`; with `spheres` (a collision spheres JSON "
      "path) or a robot that has spheres, also the clearances.");
  m.def(
      "kinematics", &scene_kinematics, py::arg("scene"), py::arg("joints") = py::none(),
      "Forward kinematics of a scene's robot (its fixed joints and spheres) at `joints` (None: the "
      "reference joints; a dict, others at their reference; or an (m,) array), with tool poses.");
}

}  // namespace shapectl::python
