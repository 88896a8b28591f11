// Python values as checked inputs. Arrays and lists of numbers: type, dtype, shape and size
// checked before anything is copied. Dicts: JSON text whose size is bounded while it is
// written, then read by the files' strict parser. What the CLI refuses in a file (a bool, a
// string, a complex number, NaN) is refused here too: TypeError for a wrong type or dtype,
// ValueError for a wrong shape, size or value, each naming the argument.
#include <cmath>
#include <limits>
#include <sstream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/joints_file.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The shapes an array argument may have: (rows, columns) with rows from min_rows to max_rows,
// or (rows,) when columns is 0; `stacked` also takes (rows * columns,) (then rows is fixed).
struct Shape {
  py::ssize_t min_rows = 0, max_rows = 0, columns = 0;
  bool stacked = false;
  std::string text;  // "an array of shape (425, 3)"
};

[[noreturn]] void refuse_type(const std::string& what, const Shape& shape,
                              const std::string& found) {
  throw py::type_error(
      InputError(what, "", "real numbers (int or float) in " + shape.text, found).what());
}

std::string type_name(const py::handle& value) {
  return py::str(py::type::of(value).attr("__name__"));
}

std::string shape_text(const py::array& a) {
  std::ostringstream out;
  out << "an array of shape (";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) out << (d ? ", " : "") << a.shape(d);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

bool is_masked(const py::handle& value) {
  return py::isinstance(value, py::module_::import("numpy.ma").attr("MaskedArray"));
}

// Integer and floating dtypes only: bool, complex, object, string, void and time are refused.
bool real_dtype(const py::dtype& d) {
  const char kind = d.kind();
  return kind == 'i' || kind == 'u' || kind == 'f';
}

bool fits(const Shape& s, py::ssize_t ndim, const py::ssize_t* dims) {
  if (s.columns == 0) return ndim == 1 && dims[0] >= s.min_rows && dims[0] <= s.max_rows;
  if (s.stacked && ndim == 1 && dims[0] == s.min_rows * s.columns) return true;
  return ndim == 2 && dims[0] >= s.min_rows && dims[0] <= s.max_rows && dims[1] == s.columns;
}

// A numpy array: everything but the final (bounded) conversion is read from its header.
void append_array(const py::array& a, const std::string& what, const Shape& s,
                  std::vector<double>& out) {
  if (is_masked(a)) refuse_type(what, s, "a masked array (fill it or drop the masked rows first)");
  if (!real_dtype(a.dtype()))
    refuse_type(what, s, "an array of dtype " + std::string(py::str(a.dtype().attr("name"))));
  if (!fits(s, a.ndim(), a.shape())) throw InputError(what, "", s.text, shape_text(a));
  const auto values = DoubleArray::ensure(a);
  out.insert(out.end(), values.data(), values.data() + values.size());
}

// One number of a list: a Python int or float, or a numpy integer or floating scalar. A bool is
// refused as `true` in a file is; an int beyond float64's range becomes +inf (then refused).
double list_number(const py::handle& x, const std::string& what, const Shape& s) {
  if (PyBool_Check(x.ptr())) refuse_type(what, s, "a list holding a bool");
  if (PyFloat_Check(x.ptr())) return PyFloat_AS_DOUBLE(x.ptr());
  if (PyLong_Check(x.ptr())) {
    const double v = PyLong_AsDouble(x.ptr());
    if (v == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      return std::numeric_limits<double>::infinity();
    }
    return v;
  }
  const py::module_ numpy = py::module_::import("numpy");
  if (py::isinstance(x, numpy.attr("integer")) || py::isinstance(x, numpy.attr("floating")))
    return py::cast<double>(py::float_(py::reinterpret_borrow<py::object>(x)));
  refuse_type(what, s, "a list holding a value of type " + type_name(x));
}

std::string list_shape_text(const py::sequence& list, py::ssize_t row, const std::string& found) {
  return "a list of " + std::to_string(py::len(list)) + " entries" +
         (row >= 0 ? " whose entry " + std::to_string(row) + " is " + found : "");
}

// A list or tuple: its length is checked before any entry is read; rows may be lists, tuples
// or numpy arrays.
void append_list(const py::sequence& list, const std::string& what, const Shape& s,
                 std::vector<double>& out) {
  const auto n = static_cast<py::ssize_t>(py::len(list));
  const bool stacked = s.stacked && n == s.min_rows * s.columns;
  if (s.columns == 0 || stacked) {
    if (!stacked && (n < s.min_rows || n > s.max_rows))
      throw InputError(what, "", s.text, list_shape_text(list, -1, ""));
    for (const py::handle x : list) out.push_back(list_number(x, what, s));
    return;
  }
  if (n < s.min_rows || n > s.max_rows)
    throw InputError(what, "", s.text, list_shape_text(list, -1, ""));
  const Shape row{.min_rows = s.columns, .max_rows = s.columns, .text = s.text};
  for (py::ssize_t r = 0; r < n; ++r) {
    const py::handle x = list[static_cast<std::size_t>(r)];
    if (py::isinstance<py::array>(x)) {
      const auto a = py::reinterpret_borrow<py::array>(x);
      if (a.ndim() != 1 || a.shape(0) != s.columns)
        throw InputError(what, "", s.text, list_shape_text(list, r, shape_text(a)));
      append_array(a, what, row, out);
    } else if (py::isinstance<py::list>(x) || py::isinstance<py::tuple>(x)) {
      const auto entry = py::reinterpret_borrow<py::sequence>(x);
      if (static_cast<py::ssize_t>(py::len(entry)) != s.columns)
        throw InputError(what, "", s.text,
                         list_shape_text(list, r, list_shape_text(entry, -1, "")));
      for (const py::handle v : entry) out.push_back(list_number(v, what, s));
    } else {
      refuse_type(what, s, list_shape_text(list, r, "a value of type " + type_name(x)));
    }
  }
}

// The values of a numpy array, list or tuple of `shape`, row-major, all finite.
Eigen::VectorXd real_values(const py::handle& value, const std::string& what, const Shape& s) {
  std::vector<double> values;
  if (py::isinstance<py::array>(value))
    append_array(py::reinterpret_borrow<py::array>(value), what, s, values);
  else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value))
    append_list(py::reinterpret_borrow<py::sequence>(value), what, s, values);
  else refuse_type(what, s, "a value of type " + type_name(value));
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isfinite(values[i])) continue;
    const auto columns = static_cast<std::size_t>(std::max<py::ssize_t>(s.columns, 1));
    std::ostringstream found;
    found << values[i] << " at " << (s.columns ? "row " : "index ") << i / columns;
    if (s.columns) found << ", column " << i % columns;
    throw InputError(what, "", "finite numbers", found.str());
  }
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

}  // namespace

Positions positions_from(const py::handle& array, int node_count, const std::string& what) {
  const py::ssize_t n = node_count;
  return real_values(array, what,
                     {.min_rows = n,
                      .max_rows = n,
                      .columns = 3,
                      .stacked = true,
                      .text = "an array of shape (" + std::to_string(n) + ", 3)"});
}

std::vector<Vec3> points_from(const py::handle& array, const std::string& what,
                              std::size_t min_points, std::size_t max_points) {
  const Eigen::VectorXd values =
      real_values(array, what,
                  {.min_rows = static_cast<py::ssize_t>(min_points),
                   .max_rows = static_cast<py::ssize_t>(max_points),
                   .columns = 3,
                   .text = "an array of shape (k, 3) with k from " + std::to_string(min_points) +
                           " to " + std::to_string(max_points)});
  std::vector<Vec3> points;
  for (Eigen::Index i = 0; i < values.size(); i += 3) points.push_back(values.segment<3>(i));
  return points;
}

Eigen::VectorXd joints_from(const py::handle& joints, const RobotModel& robot,
                            const Eigen::VectorXd& defaults) {
  if (joints.is_none()) return defaults;
  if (py::isinstance<py::dict>(joints))
    return read_joints(JsonInput(json_from(py::dict{py::arg("joints") = joints}, "joints"),
                                 "joints"),
                       robot, defaults);
  const py::ssize_t m = robot.active_count();
  return real_values(joints, "joints",
                     {.min_rows = m,
                      .max_rows = m,
                      .text = "an array of shape (" + std::to_string(m) + ",)"});
}

nlohmann::json json_from(const py::handle& value, const std::string& source,
                         std::size_t max_bytes) {
  // numpy arrays and scalars become lists and numbers, each checked before tolist copies it:
  // a real, bool or str dtype (the parser then checks them as in a file), not masked, and
  // small enough for the bytes left (every number takes at least two: a digit and a comma).
  std::size_t written = 0;
  const std::string limit = "at most " + std::to_string(max_bytes) + " bytes as JSON";
  const auto to_list = py::cpp_function([&](const py::object& o) -> py::object {
    const bool array = py::isinstance<py::array>(o);
    if (array && is_masked(o))
      throw py::type_error("a masked array (fill it or drop the masked entries first)");
    if (!array && !py::isinstance(o, py::module_::import("numpy").attr("generic")))
      throw py::type_error("not JSON serializable: " + type_name(o));
    const py::dtype d = py::reinterpret_borrow<py::object>(o.attr("dtype"));
    if (!real_dtype(d) && d.kind() != 'b' && d.kind() != 'U')
      throw py::type_error("expected numbers, got an array or scalar of dtype " +
                           std::string(py::str(d.attr("name"))));
    const auto size = py::cast<std::size_t>(o.attr("size"));
    if (size > (max_bytes - std::min(written, max_bytes)) / 2)
      throw py::value_error("expected " + limit + ", got an array of " + std::to_string(size) +
                            " values");
    return o.attr("tolist")();
  });
  const py::object encoder = py::module_::import("json").attr(
      "JSONEncoder")(py::arg("default") = to_list, py::arg("allow_nan") = false,
                     py::arg("separators") = py::make_tuple(",", ":"));
  std::string text;
  try {
    // Chunk by chunk, so the text stops growing at the limit.
    for (const py::handle chunk : encoder.attr("iterencode")(value)) {
      text += py::cast<std::string_view>(chunk);
      written = text.size();
      if (written > max_bytes) throw InputError(source, "", limit, "more");
    }
  } catch (py::error_already_set& e) {
    // The hook's and the encoder's refusals (NaN, a circular reference, a key's type), named
    // by source; a TypeError stays one.
    const std::string message = py::str(e.value());
    if (e.matches(PyExc_TypeError)) throw py::type_error(source + ": " + message);
    if (message.rfind("Out of range float", 0) == 0)
      throw InputError(source, "", "finite numbers", "a non-finite value");
    if (e.matches(PyExc_ValueError) || e.matches(PyExc_RecursionError))
      throw InputError(source, "", message);
    throw;
  }
  return parse_json_text(text, source, {.max_bytes = max_bytes});
}

}  // namespace shapectl::python
