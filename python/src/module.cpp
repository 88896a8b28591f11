// The compiled half of the `shapectl` Python package: error mapping, shared helpers, and the
// module definition that calls each concept's bind_* function (input_conversion.cpp converts
// Python values).
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/runtime/runtime_policy.hpp>

#include "bindings.hpp"

namespace shapectl::python {

const GrippedObject& SceneHandle::gripped() const {
  if (!object) throw InputError(scene->source.string(), "robot", "a robot (missing key)");
  return *object;
}

py::array_t<double> positions_array(const Positions& x) {
  py::array_t<double> out({static_cast<py::ssize_t>(x.size() / 3), py::ssize_t{3}});
  std::copy(x.data(), x.data() + x.size(), out.mutable_data());
  return out;
}

std::filesystem::path path_from(const py::handle& value, const std::string& what,
                                const std::string& expected) {
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__"))
    throw InputError(what, "", expected, std::string(py::str(py::type::of(value))));
  return py::cast<std::filesystem::path>(value);
}

TargetsInput read_targets_from(const py::handle& targets, int node_count, std::string& source,
                               std::size_t max_dict_bytes) {
  if (py::isinstance<py::dict>(targets)) {
    source = "targets";
    return read_targets(JsonInput(json_from(targets, source, max_dict_bytes), source), node_count);
  }
  const auto path = path_from(targets, "targets", "a TARGETS.json path or a dict of its schema");
  source = path.string();
  return load_targets(path, node_count);
}

std::map<std::string, Pose> tool_poses(const Scene& scene, const Eigen::VectorXd& joints) {
  std::map<std::string, Pose> tools;
  const KinematicsState state = forward_kinematics(*scene.robot->model, joints);
  for (const auto& ee : scene.robot->end_effectors) {
    const Eigen::Isometry3d& T = state.T_world_link[static_cast<std::size_t>(ee.link)];
    tools[ee.name] = {T * ee.tcp_link, T.linear()};
  }
  return tools;
}

std::vector<LimitViolation> violations_at(const RobotModel& robot, const Eigen::VectorXd& active) {
  return limit_violations(robot, robot.full_joints(active));
}

}  // namespace shapectl::python

PYBIND11_MODULE(_shapectl, m) {
  using namespace shapectl::python;
  // The process's tuning (docs/runtime.md), as the CLI has it, unless the program chose its own.
  shapectl::runtime::ensure_runtime_policy();
  m.doc() =
      "shapectl: statics, kinematics, shape optimization and the continuous controller of "
      "elastic objects held by a robot (the compiled part of the `shapectl` package).";
  // Bad input says where and what, as the CLI prints it; a failed computation is its own type.
  static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
  solver_error.doc() =
      "A computation that ran but failed (statics not converged at the start, a "
      "non-finite result, an unstable equilibrium): the CLI's exit code 2.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const shapectl::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const SolverError& e) {
      PyErr_SetString(solver_error.ptr(), e.what());
    }
  });
  bind_scene(m);
  bind_statics(m);
  bind_kinematics(m);
  bind_solve(m);
  bind_controller(m);
  bind_calibration(m);
  bind_runtime(m);
}
