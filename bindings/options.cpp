// Python values as the engine's option values, and the helpers every binding file shares.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <limits>

#include "ambfplus/errors.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {

OptionValue to_option(const py::handle& value) {
  if (value.is_none()) return {};
  if (py::isinstance<py::bool_>(value) ||
      py::isinstance(value, py::module_::import("numpy").attr("bool_"))) {
    return value.cast<bool>();
  }
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<Object>(value)) return OptionValue(&value.cast<Object&>());
  if (py::hasattr(value, "__fspath__")) {
    return py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>();
  }
  const py::handle type = py::type::of(value);
  if (py::hasattr(type, "__members__") && py::hasattr(value, "name")) {
    return py::str(value.attr("name")).cast<std::string>();  // an enum member: its name
  }
  if (py::isinstance<py::array>(value)) {
    const py::array a = py::reinterpret_borrow<py::array>(value);
    return to_option(a.ndim() == 0 ? a.attr("item")() : a.attr("tolist")());
  }
  if (py::isinstance<py::int_>(value) ||
      (PyIndex_Check(value.ptr()) && !PyFloat_Check(value.ptr()))) {
    const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
    const long long v = PyLong_AsLongLong(i.ptr());
    if (v == -1 && PyErr_Occurred()) {
      PyErr_Clear();
      throw ArgumentError("the integer " + py::str(value).cast<std::string>() + " is too large");
    }
    return std::int64_t{v};
  }
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::hasattr(value, "__float__") && !py::isinstance<py::sequence>(value)) {
    return PyFloat_AsDouble(value.ptr());  // NumPy's float32 and other real scalars
  }
  if (py::isinstance<py::dict>(value) ||
      py::isinstance(value, py::module_::import("collections.abc").attr("Mapping"))) {
    return OptionValue::mapping(to_options(value));
  }
  if (py::isinstance<py::sequence>(value) || py::hasattr(value, "__iter__")) {
    std::vector<OptionValue> items;
    for (const py::handle item : value) items.push_back(to_option(item));
    return OptionValue(std::move(items));
  }
  throw ArgumentTypeError("cannot use " + py::repr(value).cast<std::string>() + " (a " +
                          py::str(type.attr("__name__")).cast<std::string>() + ") as a value");
}

OptionMap to_options(const py::handle& mapping) {
  OptionMap out;
  const py::object items = mapping.attr("items")();
  for (const py::handle item : items) {
    const py::tuple kv = py::reinterpret_borrow<py::tuple>(item);
    out.push_back({py::str(kv[0]).cast<std::string>(), to_option(kv[1])});
  }
  return out;
}

py::array readonly(py::array array) {
  array.attr("flags").attr("writeable") = false;
  return array;
}

}  // namespace ambfplus::bindings
