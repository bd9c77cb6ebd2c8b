// The engine's typed errors, translated to Python exceptions in this one place:
//   ambfplus.Error          base of all (an Exception)
//   ambfplus.ConfigError    (Error, ValueError)        bad scene or data file; .filename
//   ambfplus.AssetNotFound  (Error, FileNotFoundError) missing file; .filename, .errno, .tried
//   ambfplus.RenderError    (Error, RuntimeError)
//   ambfplus.PluginError    (Error, RuntimeError)
// std::invalid_argument becomes ValueError (pybind11's default).

#include <cerrno>

#include "ambfplus/errors.h"
#include "bindings.h"

#include <pybind11/stl.h>

namespace ambfplus::bindings {
namespace {

PyObject* make_exception(pybind11::module_& m, const char* name, PyObject* bases) {
  const std::string qualified = std::string("ambfplus.") + name;
  PyObject* type = PyErr_NewException(qualified.c_str(), bases, nullptr);
  if (type == nullptr) throw pybind11::error_already_set();
  m.add_object(name, pybind11::handle(type));
  return type;
}

PyObject* g_error = nullptr;
PyObject* g_config_error = nullptr;
PyObject* g_asset_not_found = nullptr;
PyObject* g_render_error = nullptr;
PyObject* g_plugin_error = nullptr;

// Raises type(message) with extra attributes set on the instance.
pybind11::object with(PyObject* type, const std::string& message, const char* filename = nullptr,
                      int error_number = 0) {
  pybind11::object instance = pybind11::reinterpret_borrow<pybind11::object>(type)(message);
  if (filename != nullptr) instance.attr("filename") = filename;
  if (error_number != 0) {
    // OSError's str() is "[Errno n] strerror: 'filename'": the message goes in strerror.
    instance.attr("errno") = error_number;
    instance.attr("strerror") = message;
  }
  return instance;
}

void raise_with(PyObject* type, const std::string& message, const char* filename = nullptr,
                int error_number = 0) {
  PyErr_SetObject(type, with(type, message, filename, error_number).ptr());
}

}  // namespace

void register_errors(pybind11::module_& m) {
  g_error = make_exception(m, "Error", PyExc_Exception);
  auto pair = [](PyObject* a, PyObject* b) {
    return pybind11::make_tuple(pybind11::handle(a), pybind11::handle(b));
  };
  g_config_error = make_exception(m, "ConfigError", pair(g_error, PyExc_ValueError).ptr());
  g_asset_not_found =
      make_exception(m, "AssetNotFound", pair(g_error, PyExc_FileNotFoundError).ptr());
  g_render_error = make_exception(m, "RenderError", pair(g_error, PyExc_RuntimeError).ptr());
  g_plugin_error = make_exception(m, "PluginError", pair(g_error, PyExc_RuntimeError).ptr());

  pybind11::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const AssetNotFound& e) {
      pybind11::object error = with(g_asset_not_found, e.what(), e.path().c_str(), ENOENT);
      error.attr("tried") = pybind11::cast(e.tried());
      PyErr_SetObject(g_asset_not_found, error.ptr());
    } catch (const ConfigError& e) {
      raise_with(g_config_error, e.what(), e.file().empty() ? nullptr : e.file().c_str());
    } catch (const RenderError& e) {
      raise_with(g_render_error, e.what());
    } catch (const PluginError& e) {
      raise_with(g_plugin_error, e.what());
    } catch (const Error& e) {
      raise_with(g_error, e.what());
    }
  });
}

}  // namespace ambfplus::bindings
