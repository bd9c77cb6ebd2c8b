// AMBF description files from Python: Simulator.from_launch, World.load_launch / load_adf, name
// lookup as AMBF does it, a root body's joints in AMBF's order, and namespaces.

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

AdfLoadOptions load_options(std::optional<std::vector<int>> models, const std::vector<Path>& extra,
                            const std::vector<int>& devices, bool strict, bool load_world,
                            const std::string& prefix, const std::vector<std::string>& plugins) {
  AdfLoadOptions o;
  o.plugins = plugins;
  o.indices = std::move(models);
  for (const Path& p : extra) o.extra.push_back(p.string());
  o.devices = devices;
  o.strict = strict;
  o.load_world = load_world;
  o.namespace_prefix = prefix;
  return o;
}

std::optional<ObjectKind> parse_kind(const std::optional<std::string>& kind) {
  if (!kind) return std::nullopt;
  for (ObjectKind k : {ObjectKind::kRigidBody, ObjectKind::kJoint, ObjectKind::kCamera,
                       ObjectKind::kLight, ObjectKind::kVolume, ObjectKind::kDrill,
                       ObjectKind::kSoftBody, ObjectKind::kSensor, ObjectKind::kActuator}) {
    if (*kind == object_kind_name(k)) return k;
  }
  throw py::value_error("unknown kind '" + *kind +
                        "': expected body, joint, camera, light, volume, drill, soft body, "
                        "sensor or actuator");
}

// One object for a name: exact name first, then AMBF's lookup; KeyError says why not.
py::object get(World& w, const std::string& name, const std::optional<std::string>& kind) {
  const std::optional<ObjectKind> k = parse_kind(kind);
  if (Object* o = w.find(name); o != nullptr && (!k || o->kind() == *k)) return to_python(o);
  std::vector<Object*> found = w.lookup(name, k);
  if (found.size() > 1 && !k) {
    // AMBF's clients find bodies, cameras and lights; joints only when asked for.
    std::vector<Object*> objects;
    for (Object* o : found) {
      if (o->kind() != ObjectKind::kJoint) objects.push_back(o);
    }
    if (objects.size() == 1) found = objects;
  }
  if (found.size() == 1) return to_python(found.front());
  if (found.empty()) throw py::key_error("no object '" + name + "' in the world");
  std::string names;
  for (std::size_t i = 0; i < found.size() && i < 6; ++i) {
    names += (i ? ", " : "") + found[i]->qualified_name();
  }
  throw py::key_error("'" + name + "' is ambiguous: it matches " + std::to_string(found.size()) +
                      " objects (" + names + (found.size() > 6 ? ", ..." : "") + ")");
}

}  // namespace

void register_adf(py::module_& m) {
  py::class_<AdfReport, std::shared_ptr<AdfReport>>(m, "LoadReport",
                                                    "What loading a launch file did.")
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

  auto load_launch_into = [](World& w, const Path& path, std::optional<std::vector<int>> models,
                             const std::vector<Path>& extra, const std::vector<int>& devices,
                             bool strict, bool load_world, const std::string& prefix,
                             const std::vector<std::string>& plugins) {
    const AdfLoadOptions options =
        load_options(std::move(models), extra, devices, strict, load_world, prefix, plugins);
    py::gil_scoped_release release;
    return std::make_shared<AdfReport>(load_launch(w, path.string(), options));
  };
  const char* launch_doc =
      "Loads an AMBF launch file: its world file, then the model files at the launch indices "
      "`models` (AMBF's -l; None: index 1 unless `extra` is given), then `extra` files (-a), "
      "then the simulated multibodies of input `devices` (-i), then the launch file's and "
      "`plugins`' simulator plugins (--plugins). A model that fails is reported in the result's "
      "errors and leaves nothing behind, a plugin that fails is reported there too; "
      "strict=True raises instead.";

  auto simulator = py::reinterpret_borrow<py::class_<Simulator, std::shared_ptr<Simulator>>>(
      m.attr("Simulator"));
  simulator
      .def_static(
          "from_launch",
          [load_launch_into](const Path& path, std::optional<std::vector<int>> models,
                             const std::vector<Path>& extra, const std::vector<int>& devices,
                             bool strict, bool load_world, const std::string& prefix,
                             double time_step, const std::vector<std::string>& plugins,
                             const std::vector<std::string>& arguments) {
            SimulatorOptions options;
            options.time_step = time_step;
            auto sim = Simulator::create(options);
            sim->set_arguments(arguments);
            auto report = load_launch_into(sim->world(), path, std::move(models), extra, devices,
                                           strict, load_world, prefix, plugins);
            sim->set_load_report(report);
            return sim;
          },
          py::arg("path"), py::arg("models") = py::none(), py::arg("extra") = std::vector<Path>{},
          py::arg("devices") = std::vector<int>{}, py::arg("strict") = false,
          py::arg("load_world") = true, py::arg("namespace_prefix") = "",
          py::arg("time_step") = 0.001, py::arg("plugins") = std::vector<std::string>{},
          py::arg("arguments") = std::vector<std::string>{},
          (std::string(launch_doc) +
           " arguments: command-line arguments for simulator plugins (AMBF forwards those it "
           "does not know; Simulator.arguments). Returns a new simulator; see its load_report.")
              .c_str())
      .def_property(
          "arguments", [](Simulator& s) { return s.arguments(); },
          [](Simulator& s, std::vector<std::string> a) { s.set_arguments(std::move(a)); },
          "command-line arguments for simulator plugins (set before they load)")
      .def_property_readonly(
          "load_report",
          [](Simulator& s) -> py::object {
            if (!s.load_report()) return py::none();
            return py::cast(std::const_pointer_cast<AdfReport>(s.load_report()));
          },
          "what from_launch loaded and reported (None otherwise)")
      .def(
          "get",
          [](Simulator& s, const std::string& name, const std::optional<std::string>& kind) {
            return get(s.world(), name, kind);
          },
          py::arg("name"), py::arg("kind") = py::none(), "world.get(name, kind)");

  auto world = py::reinterpret_borrow<py::class_<World, std::shared_ptr<World>>>(m.attr("World"));
  world
      .def("load_launch", load_launch_into, py::arg("path"), py::arg("models") = py::none(),
           py::arg("extra") = std::vector<Path>{}, py::arg("devices") = std::vector<int>{},
           py::arg("strict") = false, py::arg("load_world") = true,
           py::arg("namespace_prefix") = "", py::arg("plugins") = std::vector<std::string>{},
           launch_doc)
      .def(
          "load_adf",
          [](World& w, const Path& path) {
            Model* model = nullptr;
            {
              py::gil_scoped_release release;
              model = &load_model_file(w, path.string());
            }
            return handle(model, w);
          },
          py::arg("path"),
          "Loads an AMBF model file as a new model (all or nothing) and returns it.")
      .def(
          "load_world_file",
          [](World& w, const Path& path) {
            py::gil_scoped_release release;
            load_world_file(w, path.string());
          },
          py::arg("path"),
          "Loads an AMBF world file: gravity, namespace, environment, lights and cameras.")
      .def("get", &get, py::arg("name"), py::arg("kind") = py::none(),
           "The object a name refers to: the exact name, else AMBF's lookup (qualified name "
           "'/ambf/env/l1', identifier 'BODY l1', or a unique part of either; a part that also "
           "matches joints means the one other object). KeyError when none or several match; "
           "kind ('body', 'joint', ...) narrows the search.")
      .def(
          "lookup",
          [](World& w, const std::string& query, const std::optional<std::string>& kind) {
            py::list out;
            for (Object* o : w.lookup(query, parse_kind(kind))) out.append(to_python(o));
            return out;
          },
          py::arg("query"), py::arg("kind") = py::none(),
          "Every object the query refers to (exact matches, else substring matches).")
      .def_property("namespace", &World::name_space, &World::set_name_space,
                    "namespace of models whose files name none");

  auto object =
      py::reinterpret_borrow<py::class_<Object, std::shared_ptr<Object>>>(m.attr("Object"));
  object
      .def_property("namespace", &Object::name_space, &Object::set_name_space,
                    "AMBF namespace, e.g. '/ambf/env/'")
      .def_property_readonly("qualified_name", &Object::qualified_name, "namespace + name")
      .def_property_readonly("identifier", &Object::identifier,
                             "the ADF block it was loaded from ('BODY l1'), or ''")
      .def_property_readonly(
          "attached_to", [](Object& o) { return to_python(const_cast<Object*>(o.attached_to())); })
      .def(
          "attach_to",
          [](Object& o, std::shared_ptr<Object> parent, std::optional<Eigen::Matrix4d> local) {
            Eigen::Isometry3d l = parent ? parent->pose().inverse() * o.pose() : o.pose();
            if (local) l = checked_pose(*local);
            o.attach_to(parent.get(), l);
          },
          py::arg("parent"), py::arg("local") = py::none(),
          "Rides on parent after every step at `local` (4x4 parent-from-object; default: where "
          "it is now). None detaches.");

  auto body = py::reinterpret_borrow<py::class_<RigidBody, Object, std::shared_ptr<RigidBody>>>(
      m.attr("RigidBody"));
  body.def_property_readonly(
          "joints",
          [](RigidBody& b) {
            py::list out;
            for (Joint* j : b.world().descendant_joints(b)) out.append(to_python(j));
            return out;
          },
          "The joints below this body in AMBF's order (every joint reachable from it, creation "
          "order, passive ones left out): the order of a root body's joint positions.")
      .def_property_readonly(
          "collision_mesh", [](RigidBody& b) { return b.collision().mesh; },
          "the separate collision mesh file, or '' (the visual mesh collides)")
      .def_property_readonly(
          "collision_shapes",
          [](RigidBody& b) {
            py::list out;
            for (const auto& [shape, pose] : b.collision().shapes) {
              out.append(py::make_tuple(shape_kind_name(shape.kind), Eigen::Matrix4d(pose)));
            }
            return out;
          },
          "the primitive collision parts as (shape, 4x4 pose in the body frame)");

  auto joint =
      py::reinterpret_borrow<py::class_<Joint, Object, std::shared_ptr<Joint>>>(m.attr("Joint"));
  joint
      .def_property_readonly(
          "parent_pivot", [](Joint& j) { return j.spec().parent_pivot; },
          "pivot in the parent body's frame, m")
      .def_property_readonly(
          "child_pivot", [](Joint& j) { return j.spec().child_pivot; },
          "pivot in the child body's frame, m")
      .def_property_readonly("parent_axis", [](Joint& j) { return j.spec().parent_axis; })
      .def_property_readonly("child_axis", [](Joint& j) { return j.spec().child_axis; })
      .def_property_readonly("offset", [](Joint& j) { return j.spec().offset; })
      .def_property_readonly("child_offset", [](Joint& j) { return j.spec().child_offset; })
      .def_property_readonly(
          "anchors",
          [](Joint& j) {
            const Eigen::Vector3d a = j.parent().pose() * j.spec().parent_pivot;
            const Eigen::Vector3d b = j.child().pose() * j.spec().child_pivot;
            return py::make_tuple(a, b);
          },
          "the pivot on the parent and on the child, world frame: the joint holds them "
          "together");
}

}  // namespace ambfplus::bindings
