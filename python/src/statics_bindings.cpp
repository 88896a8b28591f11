// Statics and sensitivities: shapectl.statics (what `shapectl statics` computes), and the
// model/state pair underneath (GrippedObject, ObjectState) with dx̂/dθ.
#include <optional>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

// What `shapectl statics` writes: the Newton result, the positions and, with a robot, the joints
// and tool poses.
struct StaticsSolution {
  StaticsResult result;
  Vec3 loads_total = Vec3::Zero();
  std::optional<ContactsResult> contacts;
  Positions positions;
  std::optional<Eigen::VectorXd> joints;
  std::vector<std::string> joint_names;
  std::map<std::string, Pose> tools;
};

StaticsSolution solve_statics(const SceneHandle& s, const py::object& joints_in) {
  StaticsSolution out;
  out.loads_total = s.scene->loads_total();
  if (!s.object) {
    if (!joints_in.is_none())
      throw InputError("joints", "", "joints given, but the scene has no robot");
    py::gil_scoped_release release;
    out.positions = s.scene->world_rest_positions();
    const ObjectStatics statics(*s.scene);
    out.result = statics.solve(out.positions);
    const std::optional<ObstacleContact> contact =
        statics.contact_terms(out.result.contact_scale).obstacles;
    out.contacts =
        contacts_at(contact ? &*contact : nullptr, statics.self_contact(), out.positions);
    return out;
  }
  const GrippedObject& object = *s.object;
  const Eigen::VectorXd joints = joints_from(joints_in, object.robot(), object.reference_joints());
  py::gil_scoped_release release;
  const ObjectState state =
      object.solve_from(joints, object.reference_positions(), 0, nullptr, {}, s.workspaces);
  out.result = state.statics();
  out.positions = state.positions();
  const auto contact = object.contact_at(state);
  out.contacts =
      contacts_at(contact ? &*contact : nullptr, object.statics().self_contact(), out.positions);
  out.joints = joints;
  out.joint_names = object.robot().active_joint_names();
  out.tools = tool_poses(*s.scene, joints);
  return out;
}

// shapectl.GrippedObject: the scene's gripped object (built once, when the scene loaded).
struct ObjectHandle {
  SceneHandle scene;
};

// A state held by Python, with the object it belongs to kept alive.
struct StateHandle {
  std::shared_ptr<const GrippedObject> object;
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<ObjectState> state;
};

StateHandle solve_state(const ObjectHandle& o, const py::object& joints_in,
                        const py::object& warm_start, Integer max_iterations) {
  const SceneHandle& s = o.scene;
  const GrippedObject& object = s.gripped();
  const Eigen::VectorXd joints = joints_from(joints_in, object.robot(), object.reference_joints());
  const Positions x = warm_start.is_none()
                          ? object.reference_positions()
                          : positions_from(warm_start, object.node_count(), "warm_start");
  if (max_iterations < 0) throw InputError("max_iterations", "", "a number >= 0", max_iterations);
  py::gil_scoped_release release;
  return {s.object, s.scene,
          std::make_shared<ObjectState>(
              object.solve_from(joints, x, max_iterations, nullptr, {}, s.workspaces))};
}

Eigen::MatrixXd sensitivity(const ObjectHandle&, const StateHandle& h) {
  py::gil_scoped_release release;
  try {
    return h.object->sensitivity(*h.state);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {  // an unstable state: no derivative exists
    throw SolverError(std::string("sensitivity: ") + e.what());
  }
}

}  // namespace

void bind_statics(py::module_& m) {
  py::class_<StaticsResult>(m, "StaticsResult", "How a statics solve (Newton) ended.")
      .def_property_readonly("converged", &StaticsResult::converged,
                             "Whether it converged (status == 'converged').")
      .def_property_readonly(
          "status", [](const StaticsResult& r) { return std::string(to_string(r.status)); },
          "'converged', 'not converged', 'inverted', 'singular' or 'unstable'.")
      .def_readonly("reason", &StaticsResult::reason, "Why it stopped, with numbers.")
      .def_readonly("iterations", &StaticsResult::iterations, "Newton iterations.")
      .def_readonly("factorizations", &StaticsResult::factorizations,
                    "Numeric factorizations done.")
      .def_readonly("residual", &StaticsResult::residual, "Largest nodal force at the result, N.")
      .def_readonly("energy", &StaticsResult::energy, "Energy at the result, J.");

  py::class_<StaticsSolution>(
      m, "StaticsSolution",
      "The equilibrium `shapectl statics` computes, with the fields of its RESULT.json.")
      .def_property_readonly(
          "converged", [](const StaticsSolution& s) { return s.result.converged(); },
          "Whether Newton converged.")
      .def_property_readonly(
          "status",
          [](const StaticsSolution& s) { return std::string(to_string(s.result.status)); },
          "'converged', 'not converged', 'inverted', 'singular' or 'unstable'.")
      .def_property_readonly(
          "reason", [](const StaticsSolution& s) { return s.result.reason; }, "Why Newton stopped.")
      .def_property_readonly(
          "iterations", [](const StaticsSolution& s) { return s.result.iterations; },
          "Newton iterations.")
      .def_property_readonly(
          "residual", [](const StaticsSolution& s) { return s.result.residual; },
          "Largest nodal force at the result, N.")
      .def_property_readonly(
          "energy", [](const StaticsSolution& s) { return s.result.energy; }, "Energy, J.")
      .def_readonly("result", &StaticsSolution::result, "The full StaticsResult.")
      .def_readonly("loads_total", &StaticsSolution::loads_total,
                    "Sum of the scene's applied loads, N, world frame: array of shape (3,).")
      .def_property_readonly(
          "contacts", [](const StaticsSolution& s) { return contacts_dict(s.contacts); },
          "Contacts with the scene's obstacles at the equilibrium: {'count', 'min_distance' (m or "
          "None), 'force_total' ((3,) N, the obstacles' force on the object), 'by_obstacle': "
          "{name: {'count', 'force'}}}, with self-contact also 'self': {'count', 'min_distance'} "
          "(its pairs are in neither count nor force_total); None without obstacles and "
          "self-contact (docs/contact.md).")
      .def_property_readonly(
          "positions", [](const StaticsSolution& s) { return positions_array(s.positions); },
          "Equilibrium positions, world frame, metres: array of shape (n, 3), mesh node order.")
      .def_readonly("joints", &StaticsSolution::joints,
                    "θ (rad): array of shape (m,), or None without a robot.")
      .def_readonly("joint_names", &StaticsSolution::joint_names, "Names of θ's entries.")
      .def_readonly("tools", &StaticsSolution::tools,
                    "Tool pose of each end effector at θ: {name: Pose}.");

  m.def(
      "statics", &solve_statics, py::arg("scene"), py::arg("joints") = py::none(),
      "Static equilibrium of the scene's object, held by its fixed nodes and/or by the robot at "
      "`joints` (None: the reference joints; a {name: rad} dict, others at their reference; or an "
      "array of shape (m,)). Newton from the rest shape, as `shapectl statics`. An unconverged "
      "solve is returned with converged False and its reason (the CLI writes it and exits 2). "
      "Releases the GIL while it solves.");

  py::class_<StateHandle>(
      m, "ObjectState",
      "The changing half of a gripped object (the library's ObjectState): θ, the "
      "positions and the last solve's result, with the factorization derivatives reuse. "
      "One thread at a time may use a state.")
      .def_property_readonly(
          "joints", [](const StateHandle& h) { return h.state->joints(); },
          "θ: array of shape (m,).")
      .def_property_readonly(
          "positions", [](const StateHandle& h) { return positions_array(h.state->positions()); },
          "Positions: array of shape (n, 3) (the equilibrium after a converged solve).")
      .def_property_readonly(
          "statics", [](const StateHandle& h) { return h.state->statics(); },
          "The StaticsResult of the solve that made this state.")
      .def_property_readonly(
          "tools", [](const StateHandle& h) { return tool_poses(*h.scene, h.state->joints()); },
          "Tool pose of each end effector: {name: Pose}.");

  py::class_<ObjectHandle>(
      m, "GrippedObject",
      "The object held by the robot (the library's GrippedObject): θ → x̂(θ) and dx̂/dθ. "
      "Immutable; threads may share one, each with states of its own.")
      .def(py::init([](const SceneHandle& s) {
             s.gripped();
             return ObjectHandle{s};
           }),
           py::arg("scene"), "The gripped object of a scene with a robot (ValueError otherwise).")
      .def_property_readonly(
          "node_count", [](const ObjectHandle& o) { return o.scene.gripped().node_count(); },
          "Nodes n.")
      .def_property_readonly(
          "joint_count", [](const ObjectHandle& o) { return o.scene.gripped().joint_count(); },
          "Active joints m.")
      .def_property_readonly(
          "joint_names",
          [](const ObjectHandle& o) { return o.scene.gripped().robot().active_joint_names(); },
          "The active joints, in θ order.")
      .def_property_readonly(
          "reference_joints",
          [](const ObjectHandle& o) { return o.scene.gripped().reference_joints(); },
          "θ⁰: array of shape (m,).")
      .def_property_readonly(
          "reference_positions",
          [](const ObjectHandle& o) {
            return positions_array(o.scene.gripped().reference_positions());
          },
          "x⁰, the placed rest shape: array of shape (n, 3).")
      .def(
          "solve", &solve_state, py::arg("joints") = py::none(), py::arg("warm_start") = py::none(),
          py::arg("max_iterations") = 0,
          "A new ObjectState solved at `joints` (None, a {name: rad} dict or an (m,) array), "
          "Newton "
          "from `warm_start` ((n, 3); None: the rest shape); max_iterations > 0 caps Newton. Check "
          "state.statics.converged. Releases the GIL.")
      .def(
          "sensitivity", &sensitivity, py::arg("state"),
          "dx̂/dθ at a state: array of shape (3n, m), rows x0, y0, z0, x1, …. Raises SolverError at "
          "an unstable state. Releases the GIL.");
}

}  // namespace shapectl::python
