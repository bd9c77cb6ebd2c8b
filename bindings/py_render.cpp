#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <vector>

#include "ambfplus/render/gl_info.h"
#include "ambfplus/render/window.h"
#include "ambfplus/scene/camera.h"
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

  m.def(
      "use_x11_display",
      [](std::uintptr_t display) {
        if (display == 0) throw py::value_error("use_x11_display: the display pointer is null");
        use_x11_display(reinterpret_cast<void*>(display));
      },
      py::arg("display"),
      "Puts the engine's OpenGL context on this X11 display (the address of a Display*, e.g. "
      "GLFW's glfwGetX11Display()), so windows can show cameras. Call before anything renders.");

  py::class_<Window>(m, "Window",
                     "An X11 window (GLFW's, made without a client API) showing cameras.")
      .def(py::init<unsigned long>(), py::arg("x11_window"))
      .def(
          "present",
          [](Window& w, const std::vector<std::shared_ptr<Camera>>& cameras, int width, int height,
             py::object overlay) {
            std::vector<const Camera*> list;
            for (const auto& c : cameras) list.push_back(c.get());
            const std::uint8_t* pixels = nullptr;
            py::array_t<std::uint8_t, py::array::c_style> image;
            if (!overlay.is_none()) {
              image = py::array_t<std::uint8_t, py::array::c_style>::ensure(overlay);
              if (!image || image.ndim() != 3 || image.shape(0) != height ||
                  image.shape(1) != width || image.shape(2) != 4) {
                throw py::value_error(
                    "overlay must be a uint8 (height, width, 4) RGBA array of "
                    "the window's size");
              }
              pixels = image.data();
            }
            std::vector<Frame> frames;
            {
              py::gil_scoped_release release;
              frames = w.present(list, width, height, pixels);
            }
            py::list out;
            for (const Frame& f : frames) {
              py::dict d;
              d["camera"] = f.camera;
              d["step"] = f.step;
              d["time"] = f.time;
              out.append(d);
            }
            return out;
          },
          py::arg("cameras"), py::arg("width"), py::arg("height"), py::arg("overlay") = py::none(),
          "Renders the cameras side by side into the window (width x height pixels), blends the "
          "RGBA overlay over them and shows it (GIL released); returns each view's camera, step "
          "and time.")
      .def(
          "set_lens",
          [](Window& w, std::optional<std::array<float, 4>> k, std::array<float, 3> aberration,
             std::vector<std::array<float, 2>> centres, float radius, float aspect) {
            if (!k) {
              w.set_lens(std::nullopt);
              return;
            }
            LensDistortion lens;
            lens.k = *k;
            lens.aberration = aberration;
            lens.centres = std::move(centres);
            lens.radius = radius;
            lens.aspect = aspect;
            w.set_lens(lens);
          },
          py::arg("k"), py::arg("aberration") = std::array<float, 3>{1, 1, 1},
          py::arg("centres") = std::vector<std::array<float, 2>>{}, py::arg("radius") = 0.5f,
          py::arg("aspect") = 1.0f,
          "Undoes a head-mounted display's lens distortion on every view from now on (k: the "
          "PanoTools coefficients a, b, c, d; a window pixel at r from its view's lens centre "
          "shows the image at r (a r^3 + b r^2 + c r + d); r in units of radius, a fraction of "
          "the view's width; centres: each view's lens centre as fractions of its viewport, y "
          "from the bottom; aspect: the view's physical width / height). k=None shows plain "
          "images.");
}

}  // namespace ambfplus::bindings
