// shapectl.Controller: the continuous controller (its own C++ thread) driven from Python, e.g.
// a Jupyter kernel: requests in from any Python thread, immutable snapshots out.
#include <optional>

#include <shapectl/control/controller.hpp>
#include <shapectl/server/protocol.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

struct ControllerHandle {
  std::shared_ptr<const Scene> scene;  // the controller refers to it
  std::unique_ptr<Controller> controller;
  std::shared_ptr<const std::vector<std::string>> link_names;

  Controller& get() const {
    if (!controller) throw InputError("controller", "", "an open controller (it was closed)");
    return *controller;
  }
};

struct SnapshotHandle {
  std::shared_ptr<const ControllerSnapshot> snapshot;
  std::shared_ptr<const std::vector<std::string>> link_names;
};

ControllerHandle open(const SceneHandle& s, const std::string& optimizer,
                      const std::string& gradient, bool start) {
  if (!s.scene->robot)
    throw InputError(s.scene->source.string(), "robot", "a robot to control (missing key)");
  ControllerOptions options;
  if (!parse(optimizer, &options.optimizer))
    throw InputError("optimizer", "", "one of the optimizer names", optimizer);
  if (!parse(gradient, &options.gradient))
    throw InputError("gradient", "", "one of the gradient names", gradient);
  ControllerHandle h;
  h.scene = s.scene;
  auto names = std::make_shared<std::vector<std::string>>();
  for (const auto& link : s.scene->robot->model->links()) names->push_back(link.name);
  h.link_names = std::move(names);
  py::gil_scoped_release release;
  h.controller = std::make_unique<Controller>(*h.scene, options);
  if (start) h.controller->start();
  return h;
}

// The controller takes from Python what it takes from a GUI client (server/protocol.hpp): a
// dict of at most a message's bytes, at most max_centerline_points points, every point within
// max_coordinate of the origin.
void check_protocol_point(const Vec3& p, const std::string& source, const std::string& where) {
  if (!(p.norm() <= server::max_coordinate))
    throw InputError(source, where,
                     "a point within " + std::to_string(static_cast<int>(server::max_coordinate)) +
                         " m of the origin (the GUI protocol's bound)",
                     "one " + std::to_string(p.norm()) + " m from it");
}

std::vector<Vec3> protocol_centerline(std::vector<Vec3> points, const std::string& source) {
  if (points.size() > server::max_centerline_points)
    throw InputError(source, "centerline",
                     "at most " + std::to_string(server::max_centerline_points) + " points",
                     points.size());
  for (std::size_t k = 0; k < points.size(); ++k)
    check_protocol_point(points[k], source, "centerline[" + std::to_string(k) + "]");
  return points;
}

// Targets as solve takes them: a TARGETS.json path or a dict of its schema; a centre-line goes
// to set_centerline.
void set_targets(const ControllerHandle& h, const py::object& targets) {
  Controller& c = h.get();
  std::string source;
  TargetsInput input =
      read_targets_from(targets, c.mesh().node_count(), source, server::max_message_bytes);
  input.centerline = protocol_centerline(std::move(input.centerline), source);
  for (int k = 0; k < input.targets.size(); ++k)
    check_protocol_point(input.targets.positions[static_cast<std::size_t>(k)], source,
                         "targets[" + std::to_string(k) + "].position");
  py::gil_scoped_release release;
  if (input.centerline.empty()) c.set_targets(std::move(input.targets));
  else c.set_centerline(std::move(input.centerline));
}

void close(ControllerHandle& h) {
  py::gil_scoped_release release;  // joining the thread
  h.controller.reset();
}

SnapshotHandle snapshot_of(const ControllerHandle& h, std::shared_ptr<const ControllerSnapshot> s) {
  return {std::move(s), h.link_names};
}

std::map<std::string, Pose> link_poses(const SnapshotHandle& h) {
  std::map<std::string, Pose> links;
  for (std::size_t l = 0; l < h.link_names->size(); ++l) {
    const Eigen::Isometry3d& T = h.snapshot->T_world_link[l];
    links[(*h.link_names)[l]] = {T.translation(), T.linear()};
  }
  return links;
}

}  // namespace

void bind_controller(py::module_& m) {
  using S = SnapshotHandle;
  py::class_<S>(m, "ControllerSnapshot",
                "One immutable published controller state (world frame, m, rad).")
      .def_property_readonly(
          "sequence", [](const S& s) { return s.snapshot->sequence; },
          "Increases with every publication.")
      .def_property_readonly(
          "time", [](const S& s) { return s.snapshot->time; },
          "Seconds since the controller started.")
      .def_property_readonly(
          "status", [](const S& s) { return std::string(to_string(s.snapshot->status)); },
          "'idle', 'optimizing', 'reached' (every target within the tolerance), 'best effort' "
          "(stopped above it: see unreachable), 'paused' or 'failed'.")
      .def_property_readonly(
          "tolerance", [](const S& s) { return s.snapshot->tolerance; },
          "m: a target error at most this counts as reached.")
      .def_property_readonly(
          "unreachable", [](const S& s) { return shortfall_names(s.snapshot->shortfalls); },
          "'best effort': why, of 'joint limit', 'collision', 'reach', 'buckling' (empty: a "
          "local minimum).")
      .def_property_readonly(
          "status_reason", [](const S& s) { return s.snapshot->status_reason; },
          "'best effort' or 'failed' in words, with numbers; empty otherwise.")
      .def_property_readonly(
          "joint_names", [](const S& s) { return s.snapshot->joint_names; },
          "Active joints, θ order.")
      .def_property_readonly(
          "joints", [](const S& s) { return s.snapshot->joints; },
          "θ, the current best (safe once a safe state exists): array of shape (m,).")
      .def_property_readonly(
          "lower_limits", [](const S& s) { return s.snapshot->lower_limits; },
          "Array of shape (m,).")
      .def_property_readonly(
          "upper_limits", [](const S& s) { return s.snapshot->upper_limits; },
          "Array of shape (m,).")
      .def_property_readonly("links", &link_poses, "Every link's pose: {name: Pose}.")
      .def_property_readonly(
          "positions", [](const S& s) { return positions_array(s.snapshot->positions); },
          "x̂(θ): array of shape (n, 3).")
      .def_property_readonly(
          "target_nodes",
          [](const S& s) {
            return py::array_t<int>(s.snapshot->targets.nodes.size(),
                                    s.snapshot->targets.nodes.data());
          },
          "Targeted nodes: int array of shape (k,).")
      .def_property_readonly(
          "target_positions",
          [](const S& s) {
            Positions stacked(3 * s.snapshot->targets.size());
            for (int k = 0; k < s.snapshot->targets.size(); ++k)
              stacked.segment<3>(3 * k) =
                  s.snapshot->targets.positions[static_cast<std::size_t>(k)];
            return positions_array(stacked);
          },
          "Their targets: array of shape (k, 3).")
      .def_property_readonly(
          "error_mean", [](const S& s) { return s.snapshot->error.mean; },
          "Mean target distance, m.")
      .def_property_readonly(
          "error_max", [](const S& s) { return s.snapshot->error.max; },
          "Largest target distance, m.")
      .def_property_readonly(
          "objective", [](const S& s) { return s.snapshot->objective; }, "Objective value.")
      .def_property_readonly(
          "min_clearance", [](const S& s) { return s.snapshot->min_clearance; },
          "Smallest sphere clearance, m (inf without spheres).")
      .def_property_readonly(
          "within_limits", [](const S& s) { return s.snapshot->within_limits; },
          "θ within hard limits.")
      .def_property_readonly(
          "safe", [](const S& s) { return s.snapshot->safe; }, "θ may be sent to a robot.")
      .def_property_readonly(
          "iterations", [](const S& s) { return s.snapshot->iterations; },
          "Optimizer iterations so far.")
      .def_property_readonly(
          "paused", [](const S& s) { return s.snapshot->paused; }, "Whether paused.")
      .def_property_readonly(
          "last_error", [](const S& s) { return s.snapshot->last_error; },
          "The last refused request or failed jog; empty when fine.");

  using H = ControllerHandle;
  py::class_<H>(
      m, "Controller",
      "The continuous controller: optimizes in its own thread towards the targets it is given and "
      "publishes snapshots. Every method may be called from any Python thread; none holds the GIL "
      "while it waits. Use as a context manager, or call close().")
      .def(py::init(&open), py::arg("scene"), py::kw_only(), py::arg("optimizer") = "gauss-newton",
           py::arg("gradient") = "sensitivity", py::arg("start") = true,
           "A controller for a scene with a robot, at its reference joints; start=False leaves the "
           "thread "
           "off (then step() drives it).")
      .def(
          "start",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().start();
          },
          "Starts the optimizer thread.")
      .def(
          "stop",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().stop();
          },
          "Stops the optimizer thread.")
      .def(
          "step",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().step_once();
          },
          "Without the thread: applies pending requests, then runs one optimizer iteration if one "
          "is due.")
      .def("set_targets", &set_targets, py::arg("targets"),
           "New targets: a TARGETS.json path or a dict of its schema (node targets or a "
           "centre-line) within the GUI protocol's bounds (a dict of at most 1 MB as JSON, at "
           "most 2000 centre-line points, every point within 10 m of the origin). TypeError "
           "or ValueError for bad input, nothing changed then.")
      .def(
          "set_centerline",
          [](const H& h, const py::object& points) {
            std::vector<Vec3> polyline = protocol_centerline(
                points_from(points, "centerline", 2, server::max_centerline_points), "centerline");
            py::gil_scoped_release r;
            h.get().set_centerline(std::move(polyline));
          },
          py::arg("points"),
          "A sketched centre-line, world frame, m: an array (or list of rows) of shape (k, 3), k "
          "from 2 to 2000, every point within 10 m of the origin (the GUI protocol's bounds). "
          "TypeError for a non-real dtype or a masked array, ValueError for a wrong shape, a "
          "non-finite value or a point out of bounds; nothing changed then.")
      .def(
          "clear_targets",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().clear_targets();
          },
          "Removes the targets.")
      .def(
          "pause",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().set_paused(true);
          },
          "Pauses the optimizer.")
      .def(
          "resume",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().set_paused(false);
          },
          "Resumes it.")
      .def(
          "jog",
          [](const H& h, const py::object& joints) {
            Controller& c = h.get();
            const Eigen::VectorXd theta = joints_from(joints, c.robot(), c.snapshot()->joints);
            py::gil_scoped_release r;
            c.set_joints(theta);
          },
          py::arg("joints"),
          "Only while paused: moves to `joints` (an (m,) array, or a {name: rad} dict, others "
          "kept), "
          "clamped to the hard limits; statics follows. ValueError when not paused.")
      .def(
          "reset",
          [](const H& h) {
            py::gil_scoped_release r;
            h.get().reset();
          },
          "Back to the reference joints and shape, targets cleared.")
      .def(
          "snapshot", [](const H& h) { return snapshot_of(h, h.get().snapshot()); },
          "The latest ControllerSnapshot.")
      .def(
          "wait_for_snapshot",
          [](const H& h, std::uint64_t after, Real timeout) {
            std::shared_ptr<const ControllerSnapshot> s;
            {
              py::gil_scoped_release r;
              s = h.get().wait_for_snapshot(after, timeout);
            }
            return snapshot_of(h, std::move(s));
          },
          py::arg("after"), py::arg("timeout") = 1.0,
          "Waits (GIL released) until a snapshot with sequence > `after` exists or `timeout` "
          "seconds "
          "pass; returns the latest.")
      .def_property_readonly(
          "node_count", [](const H& h) { return h.get().mesh().node_count(); }, "Nodes n.")
      .def("close", &close, "Stops the thread and frees the controller.")
      .def(
          "__enter__", [](H& h) -> H& { return h; }, py::return_value_policy::reference,
          "Returns the controller.")
      .def(
          "__exit__", [](H& h, const py::args&) { close(h); },
          "Closes the controller (see close()).");
}

}  // namespace shapectl::python
