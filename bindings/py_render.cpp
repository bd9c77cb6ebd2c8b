#include <pybind11/pybind11.h>

#include "ambfplus/render/gl_info.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {

void register_render(py::module_& m) {
  m.def(
      "gl_info",
      []() {
        GlInfo info;
        {
          py::gil_scoped_release release;
          info = gl_info();
        }
        py::dict d;
        d["vendor"] = info.vendor;
        d["renderer"] = info.renderer;
        d["version"] = info.version;
        d["glsl_version"] = info.glsl_version;
        d["profile"] = info.profile;
        d["egl_vendor"] = info.egl_vendor;
        d["egl_version"] = info.egl_version;
        d["platform"] = info.platform;
        d["device_index"] = info.device_index;
        d["device"] = info.device;
        return d;
      },
      "Describes the OpenGL context (created on first use): vendor, renderer, version, ...");
}

}  // namespace ambfplus::bindings
