#pragma once
// Number arguments that refuse what the CLI refuses. pybind11's int and float casters take True
// as 1 (a bool is an int in Python), while `true` is no number in a file: these take a Python
// int or float or a numpy integer or floating scalar, never a bool or np.bool_. A refused value
// is pybind11's TypeError ("incompatible function arguments … Invoked with: …").
#include <climits>

#include <pybind11/pybind11.h>

namespace shapectl::python {

struct Integer {  // an int argument
  int value = 0;
  operator int() const { return value; }
};

struct Real {  // a float argument (an int is fine)
  double value = 0;
  operator double() const { return value; }
};

// A Python int (not a bool) or a numpy integer: its value, false when neither or out of range.
inline bool integer_value(pybind11::handle src, long long& out) {
  const bool numpy_integer =
      pybind11::isinstance(src, pybind11::module_::import("numpy").attr("integer"));
  if (PyBool_Check(src.ptr()) || !(PyLong_Check(src.ptr()) || numpy_integer)) return false;
  const pybind11::object index =
      pybind11::reinterpret_steal<pybind11::object>(PyNumber_Index(src.ptr()));
  if (!index) {
    PyErr_Clear();
    return false;
  }
  int overflow = 0;
  out = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (PyErr_Occurred()) PyErr_Clear();
  else if (overflow == 0) return true;
  return false;
}

}  // namespace shapectl::python

namespace pybind11::detail {

template <>
struct type_caster<shapectl::python::Integer> {
  PYBIND11_TYPE_CASTER(shapectl::python::Integer, const_name("int"));
  bool load(handle src, bool) {
    long long v = 0;
    if (!shapectl::python::integer_value(src, v) || v < INT_MIN || v > INT_MAX) return false;
    value.value = static_cast<int>(v);
    return true;
  }
  static handle cast(shapectl::python::Integer v, return_value_policy, handle) {
    return PyLong_FromLong(v.value);
  }
};

template <>
struct type_caster<shapectl::python::Real> {
  PYBIND11_TYPE_CASTER(shapectl::python::Real, const_name("float"));
  bool load(handle src, bool) {
    const object numpy = module_::import("numpy");
    if (PyBool_Check(src.ptr()) ||
        !(PyFloat_Check(src.ptr()) || PyLong_Check(src.ptr()) ||
          isinstance(src, numpy.attr("floating")) || isinstance(src, numpy.attr("integer"))))
      return false;
    value.value = PyFloat_AsDouble(src.ptr());  // an int beyond float64: OverflowError, false
    if (!PyErr_Occurred()) return true;
    PyErr_Clear();
    return false;
  }
  static handle cast(shapectl::python::Real v, return_value_policy, handle) {
    return PyFloat_FromDouble(v.value);
  }
};

}  // namespace pybind11::detail
