// The compiled half of the `shapectl` Python package: error mapping, array conversions, and
// the module definition that calls each concept's bind_* function.
#include <cmath>
#include <sstream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/joints_file.hpp>
#include <shapectl/robot/kinematics.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_text(const DoubleArray& a) {
  std::ostringstream out;
  out << "an array of shape (";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) out << (d ? ", " : "") << a.shape(d);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

void require_finite(const DoubleArray& a, const std::string& what) {
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(a.data()[i]))
      throw InputError(what, "", "finite numbers", "a non-finite value");
}

}  // namespace

const GrippedObject& SceneHandle::gripped() const {
  if (!object) throw InputError(scene->source.string(), "robot", "a robot (missing key)");
  return *object;
}

py::array_t<double> positions_array(const Positions& x) {
  py::array_t<double> out({static_cast<py::ssize_t>(x.size() / 3), py::ssize_t{3}});
  std::copy(x.data(), x.data() + x.size(), out.mutable_data());
  return out;
}

Positions positions_from(const py::handle& array, int node_count, const std::string& what) {
  const auto a = DoubleArray::ensure(array);
  if (!a)
    throw InputError(what, "", "an (n, 3) array of numbers",
                     std::string(py::str(py::type::of(array))));
  const bool stacked = a.ndim() == 1 && a.shape(0) == 3 * py::ssize_t{node_count};
  const bool rows = a.ndim() == 2 && a.shape(0) == node_count && a.shape(1) == 3;
  if (!stacked && !rows)
    throw InputError(what, "", "an array of shape (" + std::to_string(node_count) + ", 3)",
                     shape_text(a));
  require_finite(a, what);
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size());
}

std::vector<Vec3> points_from(const py::handle& array, const std::string& what) {
  const auto a = DoubleArray::ensure(array);
  if (!a)
    throw InputError(what, "", "a (k, 3) array of numbers",
                     std::string(py::str(py::type::of(array))));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InputError(what, "", "an array of shape (k, 3)", shape_text(a));
  require_finite(a, what);
  std::vector<Vec3> points;
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    points.emplace_back(a.at(i, 0), a.at(i, 1), a.at(i, 2));
  return points;
}

Eigen::VectorXd joints_from(const py::handle& joints, const RobotModel& robot,
                            const Eigen::VectorXd& defaults) {
  if (joints.is_none()) return defaults;
  if (py::isinstance<py::dict>(joints))
    return read_joints(JsonInput(json_from(py::dict{py::arg("joints") = joints}, "joints"),
                                 "joints"),
                       robot, defaults);
  const auto a = DoubleArray::ensure(joints);
  if (!a)
    throw InputError("joints", "", "a {name: rad} dict or an array",
                     std::string(py::str(py::type::of(joints))));
  if (a.ndim() != 1 || a.shape(0) != robot.active_count())
    throw InputError("joints", "",
                     "an array of shape (" + std::to_string(robot.active_count()) + ",)",
                     shape_text(a));
  require_finite(a, "joints");
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size());
}

std::filesystem::path path_from(const py::handle& value, const std::string& what,
                                const std::string& expected) {
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__"))
    throw InputError(what, "", expected, std::string(py::str(py::type::of(value))));
  return py::cast<std::filesystem::path>(value);
}

TargetsInput read_targets_from(const py::handle& targets, int node_count, std::string& source) {
  if (py::isinstance<py::dict>(targets)) {
    source = "targets";
    return read_targets(JsonInput(json_from(targets, source), source), node_count);
  }
  const auto path = path_from(targets, "targets", "a TARGETS.json path or a dict of its schema");
  source = path.string();
  return load_targets(path, node_count);
}

nlohmann::json json_from(const py::handle& value, const std::string& source) {
  // numpy arrays and scalars become lists and numbers; the text then goes through the same
  // strict parser as a file, so limits and messages are the files'.
  const py::object json = py::module_::import("json");
  const py::object to_list = py::cpp_function([](const py::object& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("not JSON serializable: " + std::string(py::str(py::type::of(o))));
  });
  const std::string text = py::str(
      json.attr("dumps")(value, py::arg("default") = to_list, py::arg("allow_nan") = false));
  return parse_json_text(text, source);
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
}
