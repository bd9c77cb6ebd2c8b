// ambfplus/capture: Frame (its images as views with the frame as owner), the pass table and what
// Camera.capture calls (capture_into, with the GIL released).

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <sstream>
#include <vector>

#include "ambfplus/capture/capture.h"
#include "ambfplus/capture/frame.h"
#include "ambfplus/capture/points.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/world.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

// A NumPy view of a frame's buffer whose base is the frame, so the frame (and the buffer) lives
// as long as any view of it.
template <typename T>
py::object view(py::object frame, ImageBuffer<T>& buffer, bool drop_channel_axis) {
  if (buffer.empty()) return py::none();
  const auto h = static_cast<py::ssize_t>(buffer.height());
  const auto w = static_cast<py::ssize_t>(buffer.width());
  const auto c = static_cast<py::ssize_t>(buffer.channels());
  const auto s = static_cast<py::ssize_t>(sizeof(T));
  if (drop_channel_axis) {
    return py::array_t<T>({h, w}, {w * c * s, c * s}, buffer.data(), frame);
  }
  return py::array_t<T>({h, w, c}, {w * c * s, c * s, s}, buffer.data(), frame);
}

// Checks a caller's array and returns its data pointer.
template <typename T>
T* checked_output(const py::handle& value, const char* key,
                  std::initializer_list<py::ssize_t> shape) {
  if (!py::isinstance<py::array>(value)) {
    throw ArgumentTypeError(std::string("out['") + key + "'] must be a NumPy array");
  }
  auto array = py::reinterpret_borrow<py::array>(value);
  std::ostringstream want;
  want << "(";
  for (auto it = shape.begin(); it != shape.end(); ++it) {
    want << (it == shape.begin() ? "" : ", ") << *it;
  }
  want << (shape.size() == 1 ? ",)" : ")");
  const bool dtype_ok = array.dtype().is(py::dtype::of<T>());
  bool shape_ok = static_cast<std::size_t>(array.ndim()) == shape.size();
  if (shape_ok) {
    std::size_t i = 0;
    for (py::ssize_t d : shape)
      shape_ok = shape_ok && array.shape(static_cast<py::ssize_t>(i++)) == d;
  }
  const bool contiguous = (array.flags() & py::array::c_style) != 0;
  if (!dtype_ok || !shape_ok || !contiguous || !array.writeable()) {
    throw ArgumentError(std::string("out['") + key + "'] must be a writable C-contiguous " +
                        py::str(py::dtype::of<T>()).cast<std::string>() + " array of shape " +
                        want.str() + ", got " + py::str(array.dtype()).cast<std::string>() + " " +
                        py::str(array.attr("shape")).cast<std::string>() +
                        (contiguous ? "" : " (not C-contiguous)") +
                        (array.writeable() ? "" : " (read-only)"));
  }
  return static_cast<T*>(array.mutable_data());
}

}  // namespace

unsigned parse_passes(const py::handle& names) {
  if (py::isinstance<py::str>(names)) {
    throw ArgumentTypeError("passes must be a list of names, e.g. ['rgb', 'depth']");
  }
  unsigned passes = 0;
  for (const py::handle& n : names) passes |= parse_pass(py::str(n));
  if (passes == 0) throw ArgumentError("passes must name at least one image");
  return passes;
}

py::list pass_names(unsigned passes) {
  py::list out;
  for (const PassInfo& p : capture_passes()) {
    if (passes & p.bit) out.append(p.name);
  }
  return out;
}

namespace {

// The poses a capture records: None or False (none), True (every object), or names.
PoseRequest pose_request(const py::object& poses) {
  PoseRequest request;
  if (poses.is_none()) return request;
  if (py::isinstance<py::bool_>(poses)) {
    request.all = poses.cast<bool>();
    return request;
  }
  if (py::isinstance<py::str>(poses)) {
    throw ArgumentTypeError("poses must be True, None or a list of object names, e.g. ['drill']");
  }
  for (const py::handle& n : poses) request.names.push_back(py::str(n));
  if (request.names.empty()) {
    throw ArgumentError("poses names no object: give True for every object, or None");
  }
  return request;
}

}  // namespace

py::object capture(Camera& camera, py::object out, py::object passes, py::object poses) {
  const PoseRequest request = pose_request(poses);
  if (out.is_none()) {
    auto frame = std::make_shared<Frame>();
    // The frame's buffers decide what a capture makes.
    if (!passes.is_none()) allocate_frame(camera, *frame, parse_passes(passes));
    without_gil([&] { capture_into(camera, *frame, request); });
    return py::cast(frame);
  }
  if (!passes.is_none()) {
    throw ArgumentError("passes goes with a new frame; out's buffers already decide them");
  }
  if (py::isinstance<Frame>(out)) {
    Frame& frame = out.cast<Frame&>();
    without_gil([&] { capture_into(camera, frame, request); });
    return out;
  }
  if (py::isinstance<py::dict>(out)) {
    auto buffers = py::reinterpret_borrow<py::dict>(out);
    const py::ssize_t h = camera.height(), w = camera.width();
    const int hi = camera.height(), wi = camera.width();
    auto frame = std::make_shared<Frame>();
    CaptureBuffers targets;
    for (auto item : buffers) {
      const std::string key = py::str(item.first);
      if (key == "rgb") {
        targets.rgb = checked_output<std::uint8_t>(item.second, "rgb", {h, w, 3});
        frame->rgb.attach(targets.rgb, hi, wi, 3);
      } else if (key == "depth") {
        targets.depth = checked_output<float>(item.second, "depth", {h, w});
        frame->depth.attach(targets.depth, hi, wi, 1);
      } else if (key == "label") {
        targets.label = checked_output<std::uint16_t>(item.second, "label", {h, w});
        frame->label.attach(targets.label, hi, wi, 1);
      } else if (key == "instance") {
        targets.instance = checked_output<std::int32_t>(item.second, "instance", {h, w});
        frame->instance.attach(targets.instance, hi, wi, 1);
      } else if (key == "voxel") {
        targets.voxel = checked_output<std::int32_t>(item.second, "voxel", {h, w});
        frame->voxel.attach(targets.voxel, hi, wi, 1);
      } else if (key == "segmentation") {
        targets.segmentation = checked_output<std::uint8_t>(item.second, "segmentation", {h, w, 3});
        frame->segmentation.attach(targets.segmentation, hi, wi, 3);
      } else if (key == "points") {
        targets.points = checked_output<float>(item.second, "points", {h, w, 3});
        frame->points.attach(targets.points, hi, wi, 3);
      } else {
        throw ArgumentError("out has an unknown key '" + key + "': expected one of " +
                            ambfplus::pass_names(kAllPasses));
      }
    }
    py::object result = py::cast(frame);
    // The frame's views point into the caller's arrays: keep those alive with it.
    result.attr("_out") = buffers;
    without_gil([&] { capture_into(camera, targets, *frame, request); });
    return result;
  }
  throw ArgumentTypeError(
      "out must be None, a Frame, or a dict of arrays {'rgb': ..., 'depth': ..., 'label': ...}");
}

void declare_capture(py::module_& m) {
  py::class_<Frame, std::shared_ptr<Frame>>(m, "Frame", py::dynamic_attr(),
                                            "One capture of a camera: images, time and geometry.");
}

void define_capture(py::module_& m) {
  bound<Frame, std::shared_ptr<Frame>>(m, "Frame")
      .def_property_readonly(
          "rgb", [](py::object self) { return view(self, self.cast<Frame&>().rgb, false); },
          "uint8 (H, W, 3) RGB view of the frame's colour image (row 0 at the top), or None")
      .def_property_readonly(
          "depth", [](py::object self) { return view(self, self.cast<Frame&>().depth, true); },
          "float32 (H, W) view: metric z along the optical axis, 0 where nothing was hit")
      .def_property_readonly(
          "label", [](py::object self) { return view(self, self.cast<Frame&>().label, true); },
          "uint16 (H, W) view: the volume label id seen at each pixel, 0 elsewhere")
      .def_property_readonly(
          "instance",
          [](py::object self) { return view(self, self.cast<Frame&>().instance, true); },
          "int32 (H, W) view: the id of the object seen (meshes and volumes), 0 where nothing "
          "was hit, or None when not rendered")
      .def_property_readonly(
          "voxel", [](py::object self) { return view(self, self.cast<Frame&>().voxel, true); },
          "int32 (H, W) view: the linear index i + nx (j + ny k) of the volume voxel whose label "
          "the pixel shows, -1 elsewhere, or None when not rendered")
      .def_property_readonly(
          "segmentation",
          [](py::object self) { return view(self, self.cast<Frame&>().segmentation, false); },
          "uint8 (H, W, 3) view: flat RGB colours as AMBF's preprocessing shaders draw them (the "
          "camera's preprocessing shader where set), or None when not rendered")
      .def_property_readonly(
          "points",
          [](py::object self) -> py::object {
            Frame& f = self.cast<Frame&>();
            if (!f.points.empty()) return view(self, f.points, false);
            if (f.depth.empty()) return py::none();
            py::array_t<float> out({static_cast<py::ssize_t>(f.height),
                                    static_cast<py::ssize_t>(f.width), py::ssize_t{3}});
            capture::points_from_depth(f.depth.data(), f.intrinsics, f.width, f.height,
                                       out.mutable_data());
            return std::move(out);
          },
          "float32 (H, W, 3) organised point cloud in the camera frame (OpenCV: x right, y "
          "down, z forward), (0, 0, 0) where nothing was hit: a view of the captured points "
          "pass, or without one a new array computed from depth and the intrinsics at each "
          "access; its colours and labels are rgb and label at the same pixels")
      .def_property_readonly(
          "poses",
          [](const Frame& f) -> py::object {
            if (!f.has_poses) return py::none();
            py::dict out;
            for (const Frame::ObjectPose& p : f.poses) out[py::str(p.name)] = p.pose;
            return std::move(out);
          },
          "{name: 4x4 world-from-object pose} of the objects the capture was asked for "
          "(poses=True: every object), taken with the images at the same step; None when none "
          "were asked for")
      .def_readonly("width", &Frame::width)
      .def_readonly("height", &Frame::height)
      .def_readonly("time", &Frame::time, "simulation time of the capture, seconds")
      .def_readonly("step", &Frame::step, "simulation step index of the capture")
      .def_readonly("camera", &Frame::camera, "name of the camera")
      .def_property_readonly(
          "intrinsics", [](const Frame& f) { return Eigen::Matrix3d(f.intrinsics); },
          "3x3 K; pixel (row r, column c) is centred at (c + 0.5, r + 0.5)")
      .def_property_readonly(
          "pose", [](const Frame& f) { return Eigen::Matrix4d(f.pose); },
          "4x4 world from camera (OpenCV camera frame) at the capture")
      .def("__repr__", [](const Frame& f) {
        std::ostringstream s;
        s << "<Frame camera='" << f.camera << "' " << f.width << "x" << f.height
          << " step=" << f.step << " time=" << f.time << ">";
        return s.str();
      });

  m.def(
      "capture_passes",
      []() {
        py::list out;
        for (const PassInfo& p : capture_passes()) {
          py::dict d;
          d["name"] = p.name;
          d["dtype"] = p.dtype;
          d["channels"] = p.channels;
          d["rendered"] = p.rendered;
          d["default"] = (kDefaultPasses & p.bit) != 0;
          d["description"] = p.description;
          out.append(d);
        }
        return out;
      },
      "The capture passes, in order: dicts of name, dtype (NumPy's name), channels (1: an (H, "
      "W) image, 3: (H, W, 3)), rendered (drawn by the GPU, else computed from other passes), "
      "default (made when a camera is not told otherwise) and description");
}

}  // namespace ambfplus::bindings
