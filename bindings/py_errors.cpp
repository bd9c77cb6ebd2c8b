// The engine's typed errors, translated to Python exceptions in this one place:
//   ambfplus.Error          base of all (an Exception)
//   ambfplus.ConfigError    (Error, ValueError)        bad scene or data file; .filename
//   ambfplus.AssetNotFound  (Error, FileNotFoundError) missing file; .filename, .errno, .tried
//   ambfplus.RenderError    (Error, RuntimeError)
//   ambfplus.PluginError    (Error, RuntimeError)
//   ambfplus.ArgumentError  (Error, ValueError)        a value a caller gave cannot be used
//   ambfplus.ArgumentTypeError (ArgumentError, TypeError) a value of the wrong type, or a keyword
//                                                      option that does not exist
//   ambfplus.NotFound       (Error, KeyError)          a name or key that names nothing
//   ambfplus.OutOfRange     (Error, IndexError)        an index outside what it indexes
//   ambfplus.StateError     (Error, RuntimeError)      a call that does not fit the state
//   ambfplus.ResourceError  (Error, OSError)           a socket, port or device file
// Any other C++ exception that reaches Python (the standard library's, a dependency's) becomes
// an ambfplus.Error too, with its message; pybind11's own Python exceptions pass through.

#include <cerrno>

#include "ambfplus/errors.h"
#include "bindings.h"

#include <pybind11/stl.h>

namespace ambfplus::bindings {
namespace {

PyObject* make_exception(pybind11::module_& m, const char* name, PyObject* bases, const char* doc) {
  const std::string qualified = std::string("ambfplus.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
  if (type == nullptr) throw pybind11::error_already_set();
  m.add_object(name, pybind11::handle(type));
  return type;
}

PyObject* g_error = nullptr;
PyObject* g_config_error = nullptr;
PyObject* g_asset_not_found = nullptr;
PyObject* g_render_error = nullptr;
PyObject* g_plugin_error = nullptr;
PyObject* g_argument_error = nullptr;
PyObject* g_argument_type_error = nullptr;
PyObject* g_not_found = nullptr;
PyObject* g_out_of_range = nullptr;
PyObject* g_state_error = nullptr;
PyObject* g_resource_error = nullptr;

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

PyObject* plugin_error_type() { return g_plugin_error; }

void register_errors(pybind11::module_& m) {
  g_error = make_exception(m, "Error", PyExc_Exception, "Every error the engine raises.");
  auto pair = [](PyObject* a, PyObject* b) {
    return pybind11::make_tuple(pybind11::handle(a), pybind11::handle(b));
  };
  g_config_error = make_exception(m, "ConfigError", pair(g_error, PyExc_ValueError).ptr(),
                                  "A bad scene or data file; .filename names it.");
  g_asset_not_found =
      make_exception(m, "AssetNotFound", pair(g_error, PyExc_FileNotFoundError).ptr(),
                     "A missing file; .filename names it, .tried lists every place looked.");
  g_render_error = make_exception(m, "RenderError", pair(g_error, PyExc_RuntimeError).ptr(),
                                  "Rendering failed or cannot start (what is missing is named).");
  g_plugin_error = make_exception(m, "PluginError", pair(g_error, PyExc_RuntimeError).ptr(),
                                  "A plugin failed to load or to run.");
  g_argument_error = make_exception(m, "ArgumentError", pair(g_error, PyExc_ValueError).ptr(),
                                    "A value a caller gave cannot be used.");
  g_argument_type_error =
      make_exception(m, "ArgumentTypeError", pair(g_argument_error, PyExc_TypeError).ptr(),
                     "A value of the wrong type, or a keyword option that does not exist.");
  g_not_found = make_exception(m, "NotFound", pair(g_error, PyExc_KeyError).ptr(),
                               "A name or key that names nothing where it was looked up.");
  g_out_of_range = make_exception(m, "OutOfRange", pair(g_error, PyExc_IndexError).ptr(),
                                  "An index outside what it indexes.");
  g_state_error = make_exception(m, "StateError", pair(g_error, PyExc_RuntimeError).ptr(),
                                 "A call that does not fit the object's state.");
  g_resource_error = make_exception(m, "ResourceError", pair(g_error, PyExc_OSError).ptr(),
                                    "A socket, port or device file that cannot be used.");

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
    } catch (const ArgumentTypeError& e) {
      raise_with(g_argument_type_error, e.what());
    } catch (const ArgumentError& e) {
      raise_with(g_argument_error, e.what());
    } catch (const NotFound& e) {
      raise_with(g_not_found, e.what());
    } catch (const OutOfRange& e) {
      raise_with(g_out_of_range, e.what());
    } catch (const StateError& e) {
      raise_with(g_state_error, e.what());
    } catch (const ResourceError& e) {
      raise_with(g_resource_error, e.what());
    } catch (const Error& e) {
      raise_with(g_error, e.what());
    } catch (const pybind11::builtin_exception&) {
      throw;  // pybind11's own (value_error, stop_iteration, cast_error ...) keep their type
    } catch (const pybind11::error_already_set&) {
      throw;  // a Python exception on its way back
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const std::invalid_argument& e) {
      raise_with(g_argument_error, e.what());
    } catch (const std::out_of_range& e) {
      raise_with(g_out_of_range, e.what());
    } catch (const std::exception& e) {
      raise_with(g_error, e.what());
    }
  });
}

}  // namespace ambfplus::bindings
