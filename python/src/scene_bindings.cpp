// shapectl.Scene, shapectl.Robot and the small value types every result uses (Pose,
// LimitViolation).
#include "bindings.hpp"

namespace shapectl::python {

namespace {

SceneHandle load(const std::filesystem::path& path) {
  py::gil_scoped_release release;  // a large mesh or TetGen can take a while
  return scene_handle(load_scene(path));
}

std::vector<std::vector<int>> grip_nodes(const Scene& scene) {
  std::vector<std::vector<int>> nodes;
  for (const auto& grip : scene.grips) nodes.push_back(grip.nodes);
  return nodes;
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<Pose>(m, "Pose", "A pose in the world frame (the robot's root frame).")
      .def_readonly("position", &Pose::position, "Position, metres: array of shape (3,).")
      .def_readonly("rotation", &Pose::rotation, "Rotation matrix: array of shape (3, 3).")
      .def("__repr__", [](const Pose& p) {  // the position; the rotation is one attribute away
        return "Pose(position=[" + std::to_string(p.position.x()) + ", " +
               std::to_string(p.position.y()) + ", " + std::to_string(p.position.z()) + "])";
      });

  py::class_<LimitViolation>(m, "LimitViolation", "A joint outside its hard limits (no margin).")
      .def_readonly("joint", &LimitViolation::joint, "Joint name.")
      .def_readonly("value", &LimitViolation::value, "Its value (rad, or m for prismatic joints).")
      .def_readonly("lower", &LimitViolation::lower, "Lower limit.")
      .def_readonly("upper", &LimitViolation::upper, "Upper limit.");

  py::class_<RobotHandle>(m, "Robot", "A robot model read from URDF (immutable).")
      .def_static(
          "load",
          [](const std::filesystem::path& urdf) {
            return RobotHandle{std::make_shared<const RobotModel>(RobotModel::load_urdf_file(urdf)),
                               nullptr};
          },
          py::arg("urdf"),
          "Reads a URDF file; every movable joint is active. Raises ValueError naming the file, "
          "line and field for bad input.")
      .def_property_readonly(
          "name", [](const RobotHandle& r) { return r.model->name(); }, "The URDF robot name.")
      .def_property_readonly(
          "link_names",
          [](const RobotHandle& r) {
            std::vector<std::string> names;
            for (const auto& link : r.model->links()) names.push_back(link.name);
            return names;
          },
          "Every link, in model order.")
      .def_property_readonly(
          "joint_names", [](const RobotHandle& r) { return r.model->active_joint_names(); },
          "The active joints, in θ order.")
      .def_property_readonly(
          "lower_limits", [](const RobotHandle& r) { return r.model->lower_limits(); },
          "Lower limits of the active joints: array of shape (m,).")
      .def_property_readonly(
          "upper_limits", [](const RobotHandle& r) { return r.model->upper_limits(); },
          "Upper limits of the active joints: array of shape (m,).")
      .def_property_readonly(
          "has_collision_spheres", [](const RobotHandle& r) { return r.collisions != nullptr; },
          "Whether collision spheres come with it (a scene's robot).")
      .def_property_readonly(
          "warnings", [](const RobotHandle& r) { return r.model->warnings(); },
          "What the URDF reader skipped, one line each.");

  py::class_<SceneHandle>(
      m, "Scene",
      "A loaded scene (SCENE.json): the object, what holds it, the robot. Immutable; "
      "safe to share between threads.")
      .def_static(
          "load", &load, py::arg("path"),
          "Reads and checks SCENE.json (paths in it are relative to it). Raises ValueError "
          "with the CLI's message (file, field, expected, found) for bad or implausible input.")
      .def_static(
          "from_dict", &scene_from_dict, py::arg("d"), py::arg("base_dir") = ".",
          "A scene from a dict of SCENE.json's schema (e.g. json.load of a scene file, or "
          "to_dict()), read and checked exactly as a file: its file names (object.mesh, "
          "robot.urdf, robot.collision_spheres) are relative to `base_dir` (default: the current "
          "directory). Raises ValueError with the CLI's message, the file's name replaced by "
          "'scene'.")
      .def("to_dict", &scene_to_dict, py::arg("base_dir") = py::none(),
           "The scene as a dict of SCENE.json's schema with this scene's values (a calibrated "
           "scene's fitted material and grip offsets; the rest as its file or dict gave it): "
           "file names absolute, or relative to `base_dir` when given. Scene.from_dict(d, "
           "base_dir) reads it back; json.dump writes it as a scene file. A scene loaded from a "
           "file reads that file again.")
      .def_property_readonly(
          "source", [](const SceneHandle& s) { return s.scene->source.string(); },
          "The scene file ('scene' for a scene from a dict).")
      .def_property_readonly(
          "node_count", [](const SceneHandle& s) { return s.scene->object_mesh->node_count(); },
          "Mesh nodes n (positions arrays are (n, 3), in file order).")
      .def_property_readonly(
          "tet_count", [](const SceneHandle& s) { return s.scene->object_mesh->tet_count(); },
          "Tetrahedra in the mesh.")
      .def_property_readonly(
          "tets",
          [](const SceneHandle& s) {
            py::array_t<int> tets(
                {static_cast<py::ssize_t>(s.scene->object_mesh->tet_count()), py::ssize_t{4}});
            int* out = tets.mutable_data();
            for (const auto& t : s.scene->object_mesh->tets())
              out = std::copy(t.nodes.begin(), t.nodes.end(), out);
            return tets;
          },
          "Node indices of every tetrahedron: int array of shape (tets, 4).")
      .def_property_readonly(
          "rest_positions",
          [](const SceneHandle& s) { return positions_array(s.scene->world_rest_positions()); },
          "Rest positions placed in the world, metres: array of shape (n, 3).")
      .def_property_readonly(
          "has_robot", [](const SceneHandle& s) { return s.object != nullptr; },
          "Whether a robot holds the object (else fixed nodes do).")
      .def_property_readonly(
          "robot",
          [](const SceneHandle& s) -> py::object {
            if (!s.scene->robot) return py::none();
            return py::cast(RobotHandle{s.scene->robot->model, s.scene->robot->collisions});
          },
          "The scene's robot with its fixed joint values and collision spheres, or None.")
      .def_property_readonly(
          "joint_names",
          [](const SceneHandle& s) {
            return s.scene->robot ? s.scene->robot->model->active_joint_names()
                                  : std::vector<std::string>{};
          },
          "The active joints, in θ order (empty without a robot).")
      .def_property_readonly(
          "reference_joints",
          [](const SceneHandle& s) {
            return s.scene->robot ? s.scene->robot->reference_joints : Eigen::VectorXd();
          },
          "θ⁰, where the grips were taken: array of shape (m,).")
      .def_property_readonly(
          "end_effectors",
          [](const SceneHandle& s) {
            std::vector<std::string> names;
            if (s.scene->robot)
              for (const auto& ee : s.scene->robot->end_effectors) names.push_back(ee.name);
            return names;
          },
          "End effector names.")
      .def_property_readonly(
          "grip_nodes", [](const SceneHandle& s) { return grip_nodes(*s.scene); },
          "The nodes each grip caught, one list per grip.")
      .def_property_readonly(
          "warnings", [](const SceneHandle& s) { return s.scene->warnings; },
          "Scene checks that passed with a warning (\"file: field: what\"), one each.")
      .def("__repr__", [](const SceneHandle& s) {
        return "<shapectl.Scene " + s.scene->source.string() + ": " +
               std::to_string(s.scene->object_mesh->node_count()) + " nodes>";
      });
}

}  // namespace shapectl::python
