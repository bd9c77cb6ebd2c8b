// ambfplus/render: the GL context, windows, OpenXR sessions, and shader settings.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/render/gl_info.h"
#include "ambfplus/render/openxr.h"
#include "ambfplus/render/window.h"
#include "ambfplus/scene/camera.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

// What a display showed: each view's camera, step and time.
py::list shown(const std::vector<Frame>& frames) {
  py::list out;
  for (const Frame& f : frames) {
    py::dict d;
    d["camera"] = f.camera;
    d["step"] = f.step;
    d["time"] = f.time;
    out.append(d);
  }
  return out;
}

}  // namespace

std::optional<ShaderSpec> to_shader(const py::handle& value, const char* what) {
  if (value.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(value) && value.cast<std::string>() == "builtin") {
    return ShaderSpec{};
  }
  const std::string expected = std::string(what) +
                               " must be None, 'builtin' or a pair of file paths (vertex, "
                               "fragment)";
  if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value) ||
      py::len(value) != 2) {
    throw ArgumentTypeError(expected);
  }
  auto path = [&](const py::handle& p) {
    const std::string s = py::str(py::module_::import("os").attr("fspath")(p));
    if (s.empty()) throw ArgumentError(expected);
    return std::filesystem::absolute(s).lexically_normal().string();
  };
  auto pair = py::reinterpret_borrow<py::sequence>(value);
  return ShaderSpec{path(pair[0]), path(pair[1])};
}

py::object from_shader(const std::optional<ShaderSpec>& shader) {
  if (!shader) return py::none();
  if (shader->builtin()) return py::str("builtin");
  return py::make_tuple(shader->vertex, shader->fragment);
}

void declare_render(py::module_& m) {
  py::class_<Window>(m, "Window",
                     "An X11 window (GLFW's, made without a client API) showing cameras.");
  py::class_<OpenXrSession>(
      m, "OpenXrSession",
      "A session with the OpenXR runtime's head-mounted display, given the engine's EGL context "
      "(XR_MNDX_egl_enable). Per frame: poll_events(); while running: eyes = wait_frame(), "
      "place a camera per eye, end_frame(cameras). Raises RenderError naming the call and the "
      "runtime's result when the loader, a runtime or a headset is missing.");
}

void define_render(py::module_& m) {
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
        if (display == 0) throw ArgumentError("use_x11_display: the display pointer is null");
        use_x11_display(reinterpret_cast<void*>(display));
      },
      py::arg("display"),
      "Puts the engine's OpenGL context on this X11 display (the address of a Display*, e.g. "
      "GLFW's glfwGetX11Display()), so windows can show cameras. Call before anything renders.");

  bound<Window>(m, "Window")
      .def(py::init<unsigned long>(), py::arg("x11_window"),
           "Wraps the X11 window with this id (GLFW's glfwGetX11Window()).")
      .def(
          "present",
          [](Window& w, const std::vector<std::shared_ptr<Camera>>& cameras, int width, int height,
             py::object overlay, bool rendered) {
            std::vector<const Camera*> list;
            for (const auto& c : cameras) list.push_back(c.get());
            const std::uint8_t* pixels = nullptr;
            py::array_t<std::uint8_t, py::array::c_style> image;
            if (!overlay.is_none()) {
              image = py::array_t<std::uint8_t, py::array::c_style>::ensure(overlay);
              if (!image || image.ndim() != 3 || image.shape(0) != height ||
                  image.shape(1) != width || image.shape(2) != 4) {
                throw ArgumentError(
                    "overlay must be a uint8 (height, width, 4) RGBA array of "
                    "the window's size");
              }
              pixels = image.data();
            }
            std::vector<Frame> frames;
            {
              py::gil_scoped_release release;
              frames = w.present(list, width, height, pixels, rendered);
            }
            return shown(frames);
          },
          py::arg("cameras"), py::arg("width"), py::arg("height"), py::arg("overlay") = py::none(),
          py::arg("rendered") = false,
          "Renders the cameras side by side into the window (width x height pixels), blends the "
          "RGBA overlay over them and shows it (GIL released); returns each view's camera, step "
          "and time. rendered=True shows what the cameras last rendered for a display (an "
          "OpenXR session's end_frame) without rendering again.")
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

  m.def("openxr_built", &openxr_built,
        "True when this build has OpenXR sessions (OpenXR's headers were there at build time).");
  bound<OpenXrSession>(m, "OpenXrSession")
      .def(py::init([](const std::string& application) {
             py::gil_scoped_release release;
             return std::make_unique<OpenXrSession>(application);
           }),
           py::arg("application") = "ambfplus")
      .def_property_readonly("runtime", &OpenXrSession::runtime, "the runtime's name and version")
      .def_property_readonly("system", &OpenXrSession::system, "the headset's name")
      .def_property_readonly("eye_sizes", &OpenXrSession::eye_sizes,
                             "each eye's swapchain image size (width, height)")
      .def_property_readonly("state", &OpenXrSession::state,
                             "idle, ready, synchronized, visible, focused, stopping, "
                             "loss_pending or exiting")
      .def_property_readonly("running", &OpenXrSession::running,
                             "frames are expected (between ready and stopping)")
      .def_property_readonly("ended", &OpenXrSession::ended,
                             "the runtime ended the session: no more frames")
      .def_property_readonly("frames", &OpenXrSession::frames, "frames submitted")
      .def("poll_events", &OpenXrSession::poll_events, py::call_guard<py::gil_scoped_release>(),
           "Handles the runtime's events: begins the session when ready, ends it when stopping.")
      .def(
          "wait_frame",
          [](OpenXrSession& x) {
            std::vector<XrEye> eyes;
            {
              py::gil_scoped_release release;
              eyes = x.wait_frame();
            }
            py::list out;
            for (const XrEye& e : eyes) {
              py::dict d;
              d["pose"] = Eigen::Matrix4d(e.pose);
              d["fov"] = e.fov;
              d["size"] = std::array<int, 2>{e.width, e.height};
              out.append(d);
            }
            return out;
          },
          "Waits for the runtime's next frame and begins it (GIL released). Each eye to draw: "
          "pose (4x4, head-start from eye, OpenCV frame), fov (left, right, up, down angles, "
          "radians) and size (its swapchain image); empty when the runtime shows nothing now. "
          "end_frame must follow.")
      .def(
          "end_frame",
          [](OpenXrSession& x, const std::vector<std::shared_ptr<Camera>>& cameras) {
            std::vector<const Camera*> list;
            for (const auto& c : cameras) list.push_back(c.get());
            std::vector<Frame> frames;
            {
              py::gil_scoped_release release;
              frames = x.end_frame(list);
            }
            return shown(frames);
          },
          py::arg("cameras"),
          "Renders cameras[i] for eye i into the runtime's swapchain images and ends the frame "
          "(GIL released); each eye's camera, step and time (empty when wait_frame gave no "
          "eyes).")
      .def("request_exit", &OpenXrSession::request_exit, "Asks the runtime to stop the session.");
}

}  // namespace ambfplus::bindings
