// ambfplus/adf: what loading a launch file reported, and the readers of launch, input-device and
// colour files. (World.load_launch, load_adf and the name lookup are World's methods, in
// py_scene.cpp.)

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>

#include "ambfplus/adf/adf.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Path = std::filesystem::path;

py::list problems(const std::vector<AdfProblem>& list) {
  py::list out;
  for (const AdfProblem& p : list) out.append(py::make_tuple(p.file, p.message));
  return out;
}

py::dict launch_dict(const AdfLaunch& l) {
  py::dict d;
  d["file"] = l.file;
  d["world"] = l.world;
  d["colors"] = l.colors;
  d["input_devices"] = l.input_devices;
  d["models"] = l.models;
  py::list plugins;
  for (const AdfPlugin& p : l.plugins) {
    py::dict e;
    e["name"] = p.name;
    e["filename"] = p.filename;
    e["path"] = p.path;
    plugins.append(e);
  }
  d["plugins"] = plugins;
  return d;
}

py::dict device_dict(const AdfInputDevice& x) {
  py::dict d;
  d["identifier"] = x.identifier;
  d["hardware_name"] = x.hardware_name;
  d["haptic_gain"] = py::make_tuple(x.haptic_gain_linear, x.haptic_gain_angular);
  d["deadband"] = x.deadband;
  d["max_force"] = x.max_force;
  d["max_jerk"] = x.max_jerk;
  d["workspace_scaling"] = x.workspace_scaling;
  d["orientation_offset"] = x.orientation_offset;
  d["buttons"] = x.buttons;
  d["simulated_multibody"] = x.simulated_multibody;
  d["root_link"] = x.root_link;
  d["location"] = x.location ? py::cast(*x.location) : py::none();
  d["enable_joint_control"] = x.enable_joint_control;
  d["pair_cameras"] = x.pair_cameras;
  d["visible"] = x.visible;
  d["visible_size"] = x.visible_size;
  return d;
}

}  // namespace

void declare_adf(py::module_& m) {
  py::class_<AdfReport, std::shared_ptr<AdfReport>>(m, "LoadReport",
                                                    "What loading a launch file did.");
}

void define_adf(py::module_& m) {
  bound<AdfReport, std::shared_ptr<AdfReport>>(m, "LoadReport")
      .def_property_readonly("launch", [](const AdfReport& r) { return launch_dict(r.launch); })
      .def_property_readonly(
          "models",
          [](const AdfReport& r) {
            py::list out;
            for (Model* md : r.models) out.append(handle(md, md->world()));
            return out;
          },
          "the models loaded (the world's environment first)")
      .def_property_readonly(
          "errors", [](const AdfReport& r) { return problems(r.errors); },
          "(file, message) for every model or device that did not load")
      .def_property_readonly(
          "warnings", [](const AdfReport& r) { return problems(r.warnings); },
          "(file, message) for everything loaded with a caveat (unknown keys, dangling "
          "references, defaults taken)")
      .def_property_readonly("input_devices",
                             [](const AdfReport& r) {
                               py::list out;
                               for (const AdfInputDevice& d : r.input_devices) {
                                 out.append(device_dict(d));
                               }
                               return out;
                             })
      .def("__repr__", [](const AdfReport& r) {
        return "<LoadReport models=" + std::to_string(r.models.size()) +
               " errors=" + std::to_string(r.errors.size()) +
               " warnings=" + std::to_string(r.warnings.size()) + ">";
      });

  m.def(
      "read_launch", [](const Path& path) { return launch_dict(read_launch(path.string())); },
      py::arg("path"), "A launch file's entries as a dict, paths made absolute.");
  m.def(
      "read_input_devices",
      [](const Path& path) {
        py::list out;
        for (const AdfInputDevice& d : read_input_devices(path.string())) {
          out.append(device_dict(d));
        }
        return out;
      },
      py::arg("path"), "The devices an input-devices file lists, as dicts, in order.");
  m.def(
      "read_colors", [](const Path& path) { return read_colors(path.string()); }, py::arg("path"),
      "A colour file's named colours as RGBA in 0..1.");
}

}  // namespace ambfplus::bindings
