#include <pybind11/pybind11.h>

#include <cstdlib>

#include "ambfplus/log.h"
#include "ambfplus/version.h"
#include "bindings.h"

namespace py = pybind11;

namespace {

// Routes engine log messages to Python's logging ("ambfplus" logger), taking the GIL for it.
void log_to_python(ambfplus::LogLevel level, const std::string& message) {
  if (!Py_IsInitialized()) return;
  py::gil_scoped_acquire gil;
  try {
    py::module_::import("logging")
        .attr("getLogger")("ambfplus")
        .attr("log")(static_cast<int>(level), message);
  } catch (py::error_already_set& e) {
    e.discard_as_unraisable("ambfplus log message");
  }
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "ambfplus engine bindings (use the ambfplus package, not this module)";
  m.attr("__version__") = ambfplus::version();

  namespace b = ambfplus::bindings;
  b::register_errors(m);
  // Every class and enum first, so that every signature below names Python types.
  b::declare_io(m);
  b::declare_render(m);
  b::declare_capture(m);
  b::declare_volume(m);
  b::declare_scene(m);
  b::declare_engine(m);
  b::declare_haptics(m);
  b::declare_adf(m);
  b::declare_training(m);
  b::declare_audio(m);
  b::define_io(m);
  b::define_render(m);
  b::define_capture(m);
  b::define_volume(m);
  b::define_scene(m);
  b::define_engine(m);
  b::define_haptics(m);
  b::define_adf(m);
  b::define_training(m);
  b::define_audio(m);
  b::register_plugin(m);

  // Info and above go to Python, whose logging decides what to show (debug only on request, by
  // AMBFPLUS_LOG_LEVEL=debug, since every message takes the GIL).
  if (std::getenv("AMBFPLUS_LOG_LEVEL") == nullptr) {
    ambfplus::set_log_level(ambfplus::LogLevel::kInfo);
  }
  ambfplus::set_log_sink(&log_to_python);
  // Back to stderr before the interpreter goes away.
  py::module_::import("atexit").attr("register")(
      py::cpp_function([]() { ambfplus::set_log_sink({}); }));
}
