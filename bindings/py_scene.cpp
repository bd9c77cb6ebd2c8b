// ambfplus/scene: Simulator, World, Model, Object and the objects of a scene (RigidBody, Joint,
// SoftBody, ProximitySensor, ConstraintActuator, Camera, Light, Volume) with the kinds they take,
// and the state lock. Every method of these classes is here (World's plugin methods call
// py_plugin.cpp); the add_* methods turn keywords into specs through the engine's option tables.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "ambfplus/adf/adf.h"
#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/engine/engine.h"
#include "ambfplus/haptics/device.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"
#include "ambfplus/physics/physics.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/render/render_stats.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/soft_body.h"
#include "ambfplus/scene/step_log.h"
#include "bindings.h"
#include "enums.h"

namespace py = pybind11;

namespace ambfplus::bindings {

py::object to_python(Object* o) {
  if (o == nullptr) return py::none();
  World& w = o->world();
  switch (o->kind()) {
    case ObjectKind::kRigidBody:
      return py::cast(handle(static_cast<RigidBody*>(o), w));
    case ObjectKind::kJoint:
      return py::cast(handle(static_cast<Joint*>(o), w));
    case ObjectKind::kCamera:
      return py::cast(handle(static_cast<Camera*>(o), w));
    case ObjectKind::kLight:
      return py::cast(handle(static_cast<Light*>(o), w));
    case ObjectKind::kVolume:
      return py::cast(handle(static_cast<Volume*>(o), w));
    case ObjectKind::kDrill:
      return py::cast(handle(static_cast<Drill*>(o), w));
    case ObjectKind::kSoftBody:
      return py::cast(handle(static_cast<SoftBody*>(o), w));
    case ObjectKind::kSensor:
      return py::cast(handle(static_cast<ProximitySensor*>(o), w));
    case ObjectKind::kActuator:
      return py::cast(handle(static_cast<ConstraintActuator*>(o), w));
    case ObjectKind::kInputDevice:
      return py::cast(handle(static_cast<InputDevice*>(o), w));
  }
  return py::cast(handle(o, w));
}

namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;
using Path = std::filesystem::path;

template <typename T>
py::list to_python_list(const std::vector<T*>& objects) {
  py::list out;
  for (T* o : objects) out.append(to_python(o));
  return out;
}

OptionValue vec(const Vec3& v) { return OptionValue::from_numbers({v.x(), v.y(), v.z()}); }
OptionValue mat(const Mat4& m) {
  std::vector<double> flat;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) flat.push_back(m(r, c));
  }
  return OptionValue::from_numbers(flat);
}

// Keyword arguments after the named ones, in their order.
OptionMap with_kwargs(OptionMap named, const py::kwargs& kw) {
  for (OptionEntry& e : to_options(kw)) named.push_back(std::move(e));
  return named;
}

// Holds a world's state lock for a `with` block (acquired with the GIL released).
struct StateLock {
  std::shared_ptr<World> world;
  std::unique_lock<StateMutex> lock;
};

// A step log's rows as NumPy columns: step (int64), time, and each "<object>.<field>" (N, width),
// (N,) for one value or (N, 4, 4) for poses; flags bool, indices int32, buttons uint32, the rest
// float64.
py::dict step_log_arrays(const StepLog& log) {
  const auto n = static_cast<py::ssize_t>(log.rows());
  py::dict d;
  d["step"] = py::array_t<std::int64_t>(n, log.steps().data());
  d["time"] = py::array_t<double>(n, log.times().data());
  auto ends_with = [](const std::string& s, const char* end) {
    const std::string e(end);
    return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
  };
  for (const StepLog::Column& c : log.columns()) {
    py::array_t<double> values =
        c.width == 1 ? py::array_t<double>(n, c.values.data())
                     : py::array_t<double>({n, static_cast<py::ssize_t>(c.width)}, c.values.data());
    py::object column = values;
    if (c.width == 16) {
      column = values.attr("reshape")(n, 4, 4);  // poses: 4x4 row by row
    } else if (ends_with(c.name, ".on")) {
      column = values.attr("astype")("bool");
    } else if (ends_with(c.name, ".burr") || ends_with(c.name, ".leading")) {
      column = values.attr("astype")("int32");
    } else if (ends_with(c.name, ".buttons")) {
      column = values.attr("astype")("uint32");
    }
    d[py::str(c.name)] = column;
  }
  return d;
}

std::string repr_object(const Object& o) {
  std::ostringstream s;
  s << "<" << object_kind_name(o.kind()) << " '" << o.name() << "' id=" << o.id() << ">";
  return s.str();
}

// ---- Name lookup (AMBF's rules).

std::optional<ObjectKind> parse_kind(const std::optional<std::string>& kind) {
  if (!kind) return std::nullopt;
  return parse_object_kind(*kind);
}

// One object for a name (resolve_name: AMBF's rules); NotFound (a KeyError) says why not.
py::object get(World& w, const std::string& name, const std::optional<std::string>& kind) {
  return to_python(&resolve_name(w, name, parse_kind(kind)));
}

// ---- The add_* methods, shared by Model and World (which adds to its default model).

// A body's spec from add_body's (and add_ghost's) arguments.
RigidBodySpec body_spec(const std::string& name, const OptionalKindOrName<Shape::Kind>& shape,
                        std::optional<Vec3> size, std::optional<double> radius,
                        std::optional<double> height, std::optional<Path> mesh, double scale,
                        std::optional<Mat4> pose, std::optional<double> mass,
                        std::optional<std::vector<double>> color, std::optional<double> specular,
                        std::optional<double> shininess, const py::kwargs& physics) {
  OptionMap named;
  if (!shape.is_none()) named.push_back({"shape", to_option(shape)});
  if (size) named.push_back({"size", vec(*size)});
  if (radius) named.push_back({"radius", *radius});
  if (height) named.push_back({"height", *height});
  if (mesh) named.push_back({"mesh", mesh->string()});
  named.push_back({"scale", scale});
  if (pose) named.push_back({"pose", mat(*pose)});
  if (mass) named.push_back({"mass", *mass});
  if (color) named.push_back({"color", OptionValue::from_numbers(*color)});
  if (specular) named.push_back({"specular", *specular});
  if (shininess) named.push_back({"shininess", *shininess});
  return make_spec(name, rigid_body_options(), with_kwargs(std::move(named), physics));
}

RigidBody& add_body(Model& model, const RigidBodySpec& spec) {
  py::gil_scoped_release release;  // mesh files can take a while to read
  return model.add_body(spec);
}

Joint& add_joint(Model& model, const std::string& name, RigidBody& parent, RigidBody& child,
                 const KindOrName<JointType>& type, const py::kwargs& kw) {
  JointSpec spec;
  spec.parent = &parent;
  spec.child = &child;
  return model.add_joint(
      make_spec(name, joint_options(), with_kwargs({{"type", to_option(type)}}, kw), spec));
}

Camera& add_camera(Model& model, const std::string& name, int width, int height, double fov_y,
                   double near, double far, std::optional<Mat4> pose,
                   const std::vector<double>& background, bool shadows, int antialiasing,
                   bool looks) {
  OptionMap o{{"width", width},     {"height", height},
              {"fov_y", fov_y},     {"near", near},
              {"far", far},         {"background", OptionValue::from_numbers(background)},
              {"shadows", shadows}, {"antialiasing", antialiasing},
              {"looks", looks}};
  if (pose) o.push_back({"pose", mat(*pose)});
  return model.add_camera(make_spec(name, camera_options(), o));
}

Light& add_light(Model& model, const std::string& name, const KindOrName<LightSpec::Type>& type,
                 const Vec3& position, const Vec3& direction, const std::vector<double>& color,
                 double intensity, double spot_cutoff, double spot_exponent,
                 const Vec3& attenuation, int shadow_quality) {
  const OptionMap o{{"type", to_option(type)},         {"position", vec(position)},
                    {"direction", vec(direction)},     {"color", OptionValue::from_numbers(color)},
                    {"intensity", intensity},          {"spot_cutoff", spot_cutoff},
                    {"spot_exponent", spot_exponent},  {"attenuation", vec(attenuation)},
                    {"shadow_quality", shadow_quality}};
  return model.add_light(make_spec(name, light_options(), o));
}

Volume& add_volume(Model& model, const std::string& name, std::shared_ptr<VolumeData> data,
                   std::optional<Mat4> pose, double iso, double quality, double optical_density,
                   std::optional<double> specular, std::optional<double> shininess) {
  VolumeSpec spec;
  spec.data = std::move(data);
  OptionMap o{{"iso", iso}, {"quality", quality}, {"optical_density", optical_density}};
  if (pose) o.push_back({"pose", mat(*pose)});
  if (specular) o.push_back({"specular", *specular});
  if (shininess) o.push_back({"shininess", *shininess});
  return model.add_volume(make_spec(name, volume_options(), o, spec));
}

InputDevice& add_input_device(Model& model, const std::string& name,
                              const std::shared_ptr<Device>& device, Drill& drill,
                              const py::kwargs& kw) {
  InputDeviceSpec spec;
  spec.device = device;
  spec.drill = &drill;
  spec = make_spec(name, input_device_options(), to_options(kw), spec);
  if (spec.reference != nullptr && &spec.reference->world() != &model.world()) {
    throw ArgumentError("add_input_device(): the reference is in another world");
  }
  return ambfplus::add_input_device(model, spec);
}

// A method's docstring: what it does, then its keywords from the spec's option table (one
// source for the engine, the docs and the stubs).
template <typename Spec>
std::string with_keywords(const char* what, const OptionTable<Spec>& table) {
  std::string doc = std::string(what) + " Keywords:";
  for (const auto& o : table.options()) {
    doc += "\n  " + o.key + " (" + o.type + ")" + (o.help.empty() ? "" : ": " + o.help);
  }
  return doc;
}

template <typename Class, typename GetModel>
void def_adders(Class& cls, GetModel get_model) {
  using Self = typename Class::type;
  cls.def(
         "add_body",
         [get_model](Self& self, const std::string& name,
                     const OptionalKindOrName<Shape::Kind>& shape, std::optional<Vec3> size,
                     std::optional<double> radius, std::optional<double> height,
                     std::optional<Path> mesh, double scale, std::optional<Mat4> pose, double mass,
                     std::optional<std::vector<double>> color, std::optional<double> specular,
                     std::optional<double> shininess, const py::kwargs& physics) {
           Model& model = get_model(self);
           auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
           const RigidBodySpec spec = body_spec(name, shape, size, radius, height, mesh, scale,
                                                pose, mass, color, specular, shininess, physics);
           return handle(&add_body(model, spec), model.world());
         },
         py::arg("name"), py::arg("shape") = py::none(), py::kw_only(),
         py::arg("size") = py::none(), py::arg("radius") = py::none(),
         py::arg("height") = py::none(), py::arg("mesh") = py::none(), py::arg("scale") = 1.0,
         py::arg("pose") = py::none(), py::arg("mass") = 1.0, py::arg("color") = py::none(),
         py::arg("specular") = py::none(), py::arg("shininess") = py::none(),
         "Adds a rigid body: shape is box (size = full extents), sphere (radius), cylinder, "
         "capsule or cone (radius, height along axis, z unless axis='x' or 'y'; a capsule's "
         "height includes its caps), plane (z = 0, infinite) or mesh (mesh = file, scale; the "
         "default when mesh is given); pose is a 4x4 world-from-body matrix. Physics (mass > 0 "
         "moves under gravity; 0 is static): inertia, inertial_offset (4x4), friction, "
         "rolling_friction, restitution, linear_damping, angular_damping, kinematic, gravity "
         "((x, y, z) m/s^2: its own instead of the world's), collision (False: none), "
         "collision_mesh, collision_type (concave, convex_mesh, convex_hull, "
         "point_cloud), collision_shapes ([{shape, size/radius/height/axis, pose}]), margin, "
         "groups ([0..31]), axis.")
      .def(
          "add_ghost",
          [get_model](
              Self& self, const std::string& name, const OptionalKindOrName<Shape::Kind>& shape,
              std::optional<Vec3> size, std::optional<double> radius, std::optional<double> height,
              std::optional<Path> mesh, double scale, std::optional<Mat4> pose,
              std::optional<std::vector<double>> color, bool visible, const py::kwargs& collision) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            RigidBodySpec spec =
                body_spec(name, shape, size, radius, height, mesh, scale, pose, std::nullopt, color,
                          std::nullopt, std::nullopt, collision);
            spec.material.visible = visible;
            RigidBody* ghost = nullptr;
            {
              py::gil_scoped_release release;
              ghost = &add_ghost(model, std::move(spec));
            }
            return handle(ghost, model.world());
          },
          py::arg("name"), py::arg("shape") = py::none(), py::kw_only(),
          py::arg("size") = py::none(), py::arg("radius") = py::none(),
          py::arg("height") = py::none(), py::arg("mesh") = py::none(), py::arg("scale") = 1.0,
          py::arg("pose") = py::none(), py::arg("color") = py::none(), py::arg("visible") = true,
          "Adds a ghost object (AMBF's ghost objects): a shape as add_body takes it that "
          "touches nothing (no force, rays pass through) and reports, after every step, the "
          "bodies overlapping it (body.overlapping, Bullet's narrow phase). It moves by its pose "
          "or rides on a parent (attach_to). Collision keywords of add_body (collision_mesh, "
          "collision_type, collision_shapes, margin) shape what it tests.")
      .def(
          "add_joint",
          [get_model](Self& self, const std::string& name, RigidBody& parent, RigidBody& child,
                      const KindOrName<JointType>& type, const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            return handle(&add_joint(model, name, parent, child, type, kw), model.world());
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("type") = "revolute",
          with_keywords("Adds a joint between two bodies (type: revolute/hinge/continuous, "
                        "prismatic/slider, fixed, spring, torsion spring, p2p, cone twist, six "
                        "dof, six dof spring); pivots and axes are in each body's frame.",
                        joint_options())
              .c_str())
      .def(
          "add_camera",
          [get_model](Self& self, const std::string& name, int width, int height, double fov_y,
                      double near, double far, std::optional<Mat4> pose,
                      const std::vector<double>& background, bool shadows, int antialiasing,
                      bool looks) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            return handle(&add_camera(model, name, width, height, fov_y, near, far, pose,
                                      background, shadows, antialiasing, looks),
                          model.world());
          },
          py::arg("name"), py::arg("width") = 640, py::arg("height") = 480, py::arg("fov_y") = 0.7,
          py::arg("near") = 0.1, py::arg("far") = 10.0, py::kw_only(), py::arg("pose") = py::none(),
          py::arg("background") = std::vector<double>{0.0, 0.0, 0.0}, py::arg("shadows") = false,
          py::arg("antialiasing") = 1, py::arg("looks") = false,
          "Adds a pinhole camera (OpenCV frame: x right, y down, z forward); fov_y is the "
          "vertical field of view in radians, near and far the clipping distances in metres. "
          "shadows, antialiasing (1 = off to 4, see Camera.antialiasing) and looks (volumes' "
          "ambient "
          "occlusion, bone texture and wet highlights) change the rgb pass only.")
      .def(
          "add_light",
          [get_model](Self& self, const std::string& name, const KindOrName<LightSpec::Type>& type,
                      const Vec3& position, const Vec3& direction, const std::vector<double>& color,
                      double intensity, double spot_cutoff, double spot_exponent,
                      const Vec3& attenuation, int shadow_quality) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            return handle(&add_light(model, name, type, position, direction, color, intensity,
                                     spot_cutoff, spot_exponent, attenuation, shadow_quality),
                          model.world());
          },
          py::arg("name"), py::arg("type") = "directional", py::kw_only(),
          py::arg("position") = Vec3(0, 0, 0), py::arg("direction") = Vec3(0, 0, -1),
          py::arg("color") = std::vector<double>{1.0, 1.0, 1.0}, py::arg("intensity") = 1.0,
          py::arg("spot_cutoff") = 0.7, py::arg("spot_exponent") = 0.7,
          py::arg("attenuation") = Vec3(1, 0, 0), py::arg("shadow_quality") = 3,
          "Adds a directional, point or spot light shining along direction. A world without "
          "lights is lit by a headlight at each camera. shadow_quality: 0 casts no shadow, "
          "1..5 shadow maps of 256 to 4096 texels a side (drawn by cameras with shadows on).")
      .def(
          "add_volume",
          [get_model](Self& self, const std::string& name, std::shared_ptr<VolumeData> data,
                      std::optional<Mat4> pose, double iso, double quality, double optical_density,
                      std::optional<double> specular, std::optional<double> shininess) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            return handle(&add_volume(model, name, std::move(data), pose, iso, quality,
                                      optical_density, specular, shininess),
                          model.world());
          },
          py::arg("name"), py::arg("data"), py::kw_only(), py::arg("pose") = py::none(),
          py::arg("iso") = 0.5, py::arg("quality") = 0.5, py::arg("optical_density") = 1.0,
          py::arg("specular") = py::none(), py::arg("shininess") = py::none(),
          "Places volume data in the world; pose is world from the volume frame (centred on the "
          "grid). Several volumes may share one VolumeData. specular (0..1) and shininess (Phong "
          "exponent) set the surface's material (defaults 0.15 and 24).")
      .def(
          "add_drill",
          [get_model](Self& self, const std::string& name, Volume& volume, const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            DrillSpec spec;
            spec.volume = &volume;
            return handle(&add_drill(model, make_spec(name, drill_options(), to_options(kw), spec)),
                          model.world());
          },
          py::arg("name"), py::arg("volume"),
          with_keywords("Adds a drill working on `volume`.", drill_options()).c_str())
      .def(
          "add_input_device",
          [get_model](Self& self, const std::string& name, const std::shared_ptr<Device>& device,
                      Drill& drill, const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            return handle(&add_input_device(model, name, device, drill, kw), model.world());
          },
          py::arg("name"), py::arg("device"), py::arg("drill"),
          with_keywords("Binds a device to a drill, as a surgeon holds it.", input_device_options())
              .c_str())
      .def(
          "add_soft_body",
          [get_model](Self& self, const std::string& name, const Path& mesh, const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            SoftBodySpec spec;
            spec.mesh = mesh.string();
            spec = make_spec(name, soft_body_options(), to_options(kw), spec);
            SoftBody* body = nullptr;
            {
              py::gil_scoped_release release;  // reads a mesh file
              body = &model.add_soft_body(spec);
            }
            return handle(body, model.world());
          },
          py::arg("name"), py::arg("mesh"),
          with_keywords("Adds a soft body made from a mesh file (STL, OBJ, ...): nodes at its "
                        "distinct vertices, links along its triangle edges.",
                        soft_body_options())
              .c_str())
      .def(
          "add_sensor",
          [get_model](Self& self, const std::string& name, RigidBody& parent,
                      const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            ProximitySensorSpec spec;
            spec.parent = &parent;
            return handle(&model.add_sensor(
                              make_spec(name, proximity_sensor_options(), to_options(kw), spec)),
                          model.world());
          },
          py::arg("name"), py::arg("parent"),
          with_keywords(
              "Adds a proximity sensor fixed to parent, updated after every physics step; a ray "
              "reaches offset + direction * range (sensor frame, default +x from the origin).",
              proximity_sensor_options())
              .c_str())
      .def(
          "add_actuator",
          [get_model](Self& self, const std::string& name, RigidBody& parent,
                      const py::kwargs& kw) {
            Model& model = get_model(self);
            auto lock = lock_holding_gil(model.world());  // see the thread-safety contract
            ConstraintActuatorSpec spec;
            spec.parent = &parent;
            return handle(&model.add_actuator(
                              make_spec(name, constraint_actuator_options(), to_options(kw), spec)),
                          model.world());
          },
          py::arg("name"), py::arg("parent"),
          with_keywords(
              "Adds a constraint actuator on parent that holds bodies on request (hold 'fixed': "
              "the body keeps its pose relative to the actuator; 'point': only the point is held).",
              constraint_actuator_options())
              .c_str());
}

// ---- The classes' methods.

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

std::shared_ptr<AdfReport> load_launch_into(World& w, const Path& path,
                                            std::optional<std::vector<int>> models,
                                            const std::vector<Path>& extra,
                                            const std::vector<int>& devices, bool strict,
                                            bool load_world, const std::string& prefix,
                                            const std::vector<std::string>& plugins) {
  const AdfLoadOptions options =
      load_options(std::move(models), extra, devices, strict, load_world, prefix, plugins);
  auto lock = lock_holding_gil(w);  // the loop never steps a half-loaded launch
  py::gil_scoped_release release;
  return std::make_shared<AdfReport>(load_launch(w, path.string(), options));
}

constexpr const char* kLaunchDoc =
    "Loads an AMBF launch file: its world file, then the model files at the launch indices "
    "`models` (AMBF's -l; None: index 1 unless `extra` is given), then `extra` files (-a), then "
    "the simulated multibodies of input `devices` (-i), then the launch file's and `plugins`' "
    "simulator plugins (--plugins). A model that fails is reported in the result's errors and "
    "leaves nothing behind, a plugin that fails is reported there too; strict=True raises "
    "instead.";

// World's plugin methods; the plugins themselves (Python's adapter, PluginInfo) are in
// py_plugin.cpp.
void define_world_plugins(py::class_<World, std::shared_ptr<World>>& world) {
  world
      .def("load_plugin",
           py::overload_cast<World&, const py::object&, const py::object&,
                             const std::optional<std::string>&>(&load_plugin),
           py::arg("plugin"), py::arg("scope_object") = py::none(), py::arg("name") = py::none(),
           (std::string(kLoadPluginDoc) +
            " scope_object: None (this world), the simulator, a model or an object.")
               .c_str())
      .def_property_readonly("plugins", &plugin_infos,
                             "The attached plugins in call order: simulator, world, model, then "
                             "object scope, each in the order attached.")
      .def("reset_plugins", &reset_plugins,
           "Calls every plugin's reset() (the scene itself is not reset).")
      .def("close_plugins", &close_plugins,
           "Calls close() on every plugin (reverse call order) and lets them go; the world "
           "does it when it is destroyed.")
      // The window's input (GLFW's codes), and a key with defaults for scripts.
      .def("keyboard", &plugin_key, py::arg("key"), py::arg("scancode"), py::arg("action"),
           py::arg("mods"), "Gives the plugins a key event (GLFW codes).")
      .def("mouse_button", &plugin_mouse_button, py::arg("button"), py::arg("action"),
           py::arg("mods"), "Gives the plugins a mouse button event (GLFW codes).")
      .def("mouse_move", &plugin_mouse_move, py::arg("x"), py::arg("y"),
           "Gives the plugins the mouse's position (pixels).")
      .def("mouse_scroll", &plugin_mouse_scroll, py::arg("dx"), py::arg("dy"),
           "Gives the plugins a scroll event.")
      .def("send_key", &plugin_key, py::arg("key"), py::arg("scancode") = 0, py::arg("action") = 1,
           py::arg("mods") = 0,
           "Gives the plugins a key event (GLFW's codes; action 0 release, 1 press, 2 repeat).");
}

void define_simulator(py::class_<Simulator, std::shared_ptr<Simulator>>& simulator) {
  simulator
      .def(py::init([](double time_step, const std::string& world_name) {
             SimulatorOptions options;
             options.time_step = time_step;
             options.world_name = world_name;
             return engine::create_simulator(options);
           }),
           py::arg("time_step") = 0.001, py::arg("world_name") = "World")
      .def_property_readonly("world", [](Simulator& s) { return handle(&s.world(), s.world()); })
      .def(
          "step",
          [](Simulator& s, std::int64_t n) {
            refuse_during_loop(s.world(), "Simulator.step");
            py::gil_scoped_release release;
            s.step(n);
          },
          py::arg("n") = 1,
          "Advances the world by n fixed steps. StateError while a RealTimeLoop steps the "
          "world.")
      .def_static(
          "from_launch",
          [](const Path& path, std::optional<std::vector<int>> models,
             const std::vector<Path>& extra, const std::vector<int>& devices, bool strict,
             bool load_world, const std::string& prefix, double time_step,
             const std::vector<std::string>& plugins, const std::vector<std::string>& arguments) {
            SimulatorOptions options;
            options.time_step = time_step;
            auto sim = engine::create_simulator(options);
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
          (std::string(kLaunchDoc) +
           " arguments: command-line arguments for simulator plugins (AMBF forwards those it "
           "does not know; Simulator.arguments). Returns a new simulator; see its load_report.")
              .c_str())
      .def_property(
          "arguments", [](Simulator& s) { return s.arguments(); },
          [](Simulator& s, std::vector<std::string> a) { s.set_arguments(std::move(a)); },
          "command-line arguments for simulator plugins (set before they load)")
      .def_property_readonly(
          "load_report",
          [](Simulator& s) -> std::shared_ptr<AdfReport> {
            return std::const_pointer_cast<AdfReport>(s.load_report());
          },
          "what from_launch loaded and reported (None otherwise)")
      .def(
          "get",
          [](Simulator& s, const std::string& name, const std::optional<std::string>& kind) {
            return get(s.world(), name, kind);
          },
          py::arg("name"), py::arg("kind") = py::none(), "world.get(name, kind)")
      .def("load_plugin",
           py::overload_cast<Simulator&, const py::object&, const std::optional<std::string>&>(
               &load_plugin),
           py::arg("plugin"), py::arg("name") = py::none(),
           (std::string(kLoadPluginDoc) + " The plugin is attached to the simulator.").c_str());
}

void define_world_logs(py::class_<World, std::shared_ptr<World>>& world) {
  world
      .def(
          "start_step_log",
          [](World& w, const std::vector<Object*>& objects) {
            std::vector<const Object*> logged(objects.begin(), objects.end());
            py::gil_scoped_release release;
            w.start_step_log(logged);
          },
          py::arg("objects"),
          "Logs every step's state of these objects from now on (poses; drills: goal, force, "
          "on, burr; input devices: readings and force); take_step_log() drains it.")
      .def(
          "stop_step_log",
          [](World& w) {
            py::gil_scoped_release release;
            w.stop_step_log();
          },
          "Stops logging steps (rows not taken are dropped).")
      .def(
          "take_step_log",
          [](World& w) {
            StepLog log(std::vector<StepLogColumns>{});
            {
              py::gil_scoped_release release;
              log = w.take_step_log();
            }
            return step_log_arrays(log);
          },
          "The steps logged since the last call: {'step', 'time', '<object>.<field>': ...}.");
}

void define_world_adf(py::class_<World, std::shared_ptr<World>>& world) {
  world
      .def("load_launch", &load_launch_into, py::arg("path"), py::arg("models") = py::none(),
           py::arg("extra") = std::vector<Path>{}, py::arg("devices") = std::vector<int>{},
           py::arg("strict") = false, py::arg("load_world") = true,
           py::arg("namespace_prefix") = "", py::arg("plugins") = std::vector<std::string>{},
           kLaunchDoc)
      .def(
          "load_adf",
          [](World& w, const Path& path) {
            auto lock = lock_holding_gil(w);
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
            auto lock = lock_holding_gil(w);
            py::gil_scoped_release release;
            load_world_file(w, path.string());
          },
          py::arg("path"),
          "Loads an AMBF world file: gravity, namespace, environment, lights and cameras.")
      .def(
          "load_volumes",
          [](World& w, const Path& path, std::optional<Path> labels) {
            auto lock = lock_holding_gil(w);
            std::vector<Volume*> loaded;
            {
              py::gil_scoped_release release;
              loaded = load_adf_volumes(w, path.string(), labels ? labels->string() : "");
            }
            return to_python_list(loaded);
          },
          py::arg("path"), py::arg("labels") = py::none(),
          "Loads the volumes: of an AMBF model file (its bodies and joints come with ADF "
          "loading) into a new model, then the drills: it declares on them (ambfplus "
          "extension); labels (CSV/YAML) overrides their label tables. Returns the volumes.")
      .def("get", &get, py::arg("name"), py::arg("kind") = py::none(),
           "The object a name refers to: the exact name, else AMBF's lookup (qualified name "
           "'/ambf/env/l1', identifier 'BODY l1', or a unique part of either; a part that also "
           "matches joints means the one other object). KeyError (ambfplus.NotFound) when none "
           "or several match; kind ('body', 'joint', ...) narrows the search.")
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
}

// One object's state as World.read_state copies it under the lock: plain C++, no Python.
struct ObjectState {
  Mat4 pose;
  std::optional<Eigen::Matrix3d> intrinsics;             // cameras
  std::optional<Vec3> force;                             // drills
  std::vector<std::pair<std::string, double>> critical;  // drills: label name, metres
};

py::dict read_state(World& w, const std::vector<std::shared_ptr<Object>>& objects) {
  for (const auto& o : objects) {
    if (!o) throw py::type_error("World.read_state: expected objects of this world, got None");
    if (&o->world() != &w)
      throw py::value_error("World.read_state: " + o->describe() + " belongs to another world");
  }
  double time = 0.0;
  std::vector<ObjectState> states(objects.size());
  {
    // The GIL is released before the lock is taken and taken back after it is given back: no
    // other Python thread can keep a real-time loop waiting while this one holds the lock.
    py::gil_scoped_release release;
    auto lock = w.lock_state_for_copy();
    time = w.time();
    for (std::size_t i = 0; i < objects.size(); ++i) {
      Object* o = objects[i].get();
      ObjectState& s = states[i];
      s.pose = o->pose().matrix();
      if (const auto* c = dynamic_cast<const Camera*>(o)) s.intrinsics = c->intrinsics();
      if (const auto* d = dynamic_cast<const Drill*>(o)) {
        s.force = d->force();
        s.critical = critical_distances_by_name(*d);
      }
    }
  }
  py::list out;
  for (const ObjectState& s : states) {
    py::dict d;
    d["pose"] = s.pose;
    if (s.intrinsics) d["intrinsics"] = *s.intrinsics;
    if (s.force) {
      d["force"] = *s.force;
      py::dict critical;
      for (const auto& [name, distance] : s.critical) critical[py::str(name)] = distance;
      d["critical_distances"] = critical;
    }
    out.append(d);
  }
  py::dict result;
  result["time"] = time;
  result["objects"] = out;
  return result;
}

void define_world(py::class_<World, std::shared_ptr<World>>& world) {
  world
      .def(py::init([](double time_step, const std::string& name) {
             SimulatorOptions options;
             options.time_step = time_step;
             options.world_name = name;
             auto sim = engine::create_simulator(options);
             return handle(&sim->world(), sim->world());
           }),
           py::arg("time_step") = 0.001, py::arg("name") = "World",
           "Creates a simulator with an empty world and returns the world.")
      .def_property_readonly("name", &World::name)
      .def_property_readonly("simulator", [](World& w) { return w.simulator().shared_from_this(); })
      .def_property_readonly("time", &World::time, "simulation time, seconds")
      .def_property_readonly("step_index", &World::step_index, "fixed steps taken so far")
      .def_property_readonly("time_step", &World::time_step, "seconds per fixed step")
      .def(
          "step",
          [](World& w, std::int64_t n) {
            refuse_during_loop(w, "World.step");
            py::gil_scoped_release release;
            w.step(n);
          },
          py::arg("n") = 1,
          "Advances the clock by n fixed steps. StateError while a RealTimeLoop steps the "
          "world.")
      .def_property_readonly("default_model",
                             [](World& w) { return handle(&w.default_model(), w); })
      .def_property_readonly("models",
                             [](World& w) {
                               py::list out;
                               for (Model* m : w.models()) out.append(handle(m, w));
                               return out;
                             })
      .def(
          "add_model",
          [](World& w, const std::string& name) {
            auto lock = lock_holding_gil(w);
            return handle(&w.add_model(name), w);
          },
          py::arg("name"), "Adds an empty model (a group of objects).")
      .def("__getitem__",
           [](World& w, const std::string& name) {
             Object* o = w.find(name);  // by key (Object::key)
             if (o == nullptr) throw NotFound(name);
             return to_python(o);
           })
      .def("__contains__",
           [](World& w, const std::string& name) { return w.find(name) != nullptr; })
      .def("__len__", [](World& w) { return w.objects().size(); })
      .def_property_readonly("objects", [](World& w) { return to_python_list(w.objects()); })
      .def_property_readonly(
          "bodies", [](World& w) { return to_python_list(w.objects_of_kind<RigidBody>()); })
      .def_property_readonly("cameras",
                             [](World& w) { return to_python_list(w.objects_of_kind<Camera>()); })
      .def_property_readonly("lights",
                             [](World& w) { return to_python_list(w.objects_of_kind<Light>()); })
      .def_property_readonly("volumes",
                             [](World& w) { return to_python_list(w.objects_of_kind<Volume>()); })
      .def_property_readonly("joints",
                             [](World& w) { return to_python_list(w.objects_of_kind<Joint>()); })
      .def_property_readonly("drills",
                             [](World& w) { return to_python_list(w.objects_of_kind<Drill>()); })
      .def_property_readonly(
          "input_devices",
          [](World& w) { return to_python_list(w.objects_of_kind<InputDevice>()); })
      .def_property(
          "gravity", [](World& w) { return physics::physics_of(w).gravity(); },
          [](World& w, const Eigen::Vector3d& g) { physics::physics_of(w).set_gravity(g); },
          "m/s^2, world frame")
      .def_property(
          "shader", [](World& w) { return from_shader(w.shader()); },
          [](World& w, const py::object& v) { w.set_shader(to_shader(v, "shader")); },
          "the shader of bodies whose model and own material name none (AMBF's world "
          "`shaders`): None (the engine's own), 'builtin', or (vertex_path, fragment_path)")
      .def("lock", &state_lock,
           "A context manager holding the world's state lock: a real-time loop's steps and "
           "captures from other threads wait meanwhile. Python may run other threads while "
           "it is held (the GIL changes hands), so hold it for a few lines at most; to read "
           "state for another thread, use read_state.")
      .def("read_state", &read_state, py::arg("objects"),
           "One consistent read of several objects, in one call that holds the world's lock "
           "with the GIL released (nothing else of Python runs under it, so a real-time loop "
           "never waits for Python). Returns {'time': s, 'objects': [one dict per object, in "
           "order]}; each has 'pose' (4x4), a camera's 'intrinsics' (3x3), a drill's 'force' "
           "(N, world frame) and 'critical_distances' ({structure: metres}).")
      .def("__repr__", [](World& w) {
        std::ostringstream s;
        s << "<World '" << w.name() << "' objects=" << w.objects().size()
          << " step=" << w.step_index() << ">";
        return s.str();
      });
  define_world_logs(world);
  define_world_adf(world);
  define_world_plugins(world);
  def_adders(world, [](World& w) -> Model& { return w.default_model(); });
}

void define_model(py::class_<Model, std::shared_ptr<Model>>& model) {
  model.def_property_readonly("name", &Model::name)
      .def_property_readonly("world", [](Model& md) { return handle(&md.world(), md.world()); })
      .def_property(
          "shader", [](Model& md) { return from_shader(md.shader()); },
          [](Model& md, const py::object& v) { md.set_shader(to_shader(v, "shader")); },
          "the shader of its bodies that name none (AMBF's model `shaders`): None (the world's), "
          "'builtin' (the engine's own), or (vertex_path, fragment_path)")
      .def_property_readonly("objects", [](Model& md) { return to_python_list(md.objects()); })
      .def("__repr__", [](Model& md) { return "<Model '" + md.name() + "'>"; });
  def_adders(model, [](Model& md) -> Model& { return md; });
}

void define_object(py::class_<Object, std::shared_ptr<Object>>& object) {
  object
      .def_property_readonly("name", &Object::name,
                             "the name it was declared with; two namespaces may each have one")
      .def_property_readonly("key", &Object::key,
                             "its name unique in the world, as AMBF's client keys it: the "
                             "namespace below /ambf/env/ and the name ('psm1/baselink'), the "
                             "bare name in the root namespace; legends and recordings use it")
      .def_property_readonly("id", &Object::id, "stable instance id (>= 1) used by segmentation")
      .def_property_readonly("kind", [](Object& o) { return object_kind_name(o.kind()); })
      .def_property_readonly("model", [](Object& o) { return handle(&o.model(), o.world()); })
      .def_property(
          "pose", [](Object& o) { return Mat4(o.pose().matrix()); },
          [](Object& o, const Mat4& m) { o.set_pose(checked_pose(m, o)); },
          "4x4 world-from-object rigid transform (a copy; assign to change it)")
      .def_property(
          "namespace", &Object::name_space,
          [](Object& o, std::string ns) {
            auto lock = lock_holding_gil(o.world());
            o.set_name_space(std::move(ns));
          },
          "AMBF namespace, e.g. '/ambf/env/' (setting it changes the key; a key taken is an "
          "ArgumentError)")
      .def_property_readonly("qualified_name", &Object::qualified_name, "namespace + name")
      .def_property_readonly("identifier", &Object::identifier,
                             "the ADF block it was loaded from ('BODY l1'), or ''")
      .def_property_readonly(
          "attached_to", [](Object& o) { return to_python(const_cast<Object*>(o.attached_to())); })
      .def(
          "attach_to",
          [](Object& o, std::shared_ptr<Object> parent, std::optional<Mat4> local) {
            Eigen::Isometry3d l = parent ? parent->pose().inverse() * o.pose() : o.pose();
            if (local) l = checked_pose(*local, o, "local");
            o.attach_to(parent.get(), l);
          },
          py::arg("parent"), py::arg("local") = py::none(),
          "Rides on parent after every step at `local` (4x4 parent-from-object; default: where "
          "it is now). None detaches.")
      .def("__repr__", &repr_object);
}

void define_camera(py::class_<Camera, Object, std::shared_ptr<Camera>>& camera) {
  camera.def_property_readonly("width", &Camera::width)
      .def_property_readonly("height", &Camera::height)
      .def_property_readonly(
          "publish",
          [](Camera& c) {
            const CameraPublish& p = c.publish();
            py::dict d;
            d["image"] = p.image;
            d["image_interval"] = p.image_interval;
            d["depth"] = p.depth;
            d["depth_interval"] = p.depth_interval;
            d["depth_noise"] =
                p.depth_noise
                    ? py::cast(std::vector<double>{p.noise_mean, p.noise_std, p.noise_bias})
                    : py::none();
            return d;
          },
          "what an ADF asked it to publish: image/depth flags and intervals (every n-th "
          "render), depth noise (mean, std_dev, bias) or None")
      .def_property("fov_y", &Camera::fov_y, &Camera::set_fov_y,
                    "vertical field of view, radians (the principal point stays)")
      .def_property_readonly("near", &Camera::near)
      .def_property_readonly("far", &Camera::far)
      .def_property_readonly("intrinsics", &Camera::intrinsics,
                             "3x3 K: fx = fy = H / (2 tan(fov_y / 2)), cx = W / 2, cy = H / 2; "
                             "pixel (row r, column c) is centred at (c + 0.5, r + 0.5)")
      .def_property_readonly("projection", &Camera::projection,
                             "4x4 OpenGL clip-from-camera matrix used to render")
      .def("look_at", &Camera::look_at, py::arg("eye"), py::arg("target"),
           py::arg("up") = Vec3(0, 0, 1),
           "Places the camera at eye looking at target, with image up along up.")
      .def("capture", &capture, py::arg("out") = py::none(), py::arg("passes") = py::none(),
           py::arg("poses") = py::none(),
           "Renders (GIL released) and returns a Frame of NumPy views. passes: the images to "
           "render (names from capture_passes(); default camera.passes), and only those. "
           "out=Frame refills that frame's images in place; out={'rgb': a, 'depth': b, ...} "
           "renders into preallocated arrays. poses: object names (or True for all) whose world "
           "poses the frame records in frame.poses, taken with the images.")
      .def_property(
          "preprocessing_shader", [](Camera& c) { return from_shader(c.preprocessing_shader()); },
          [](Camera& c, const py::object& v) {
            c.set_preprocessing_shader(to_shader(v, "preprocessing_shader"));
          },
          "AMBF's `preprocessing shaders`: what the segmentation pass draws meshes with (volumes "
          "keep their label colours); None or 'builtin': the engine's equivalent of AMBF's")
      .def_property(
          "passes", [](Camera& c) { return pass_names(c.passes()); },
          [](Camera& c, const py::object& names) { c.set_passes(parse_passes(names)); },
          "what a capture renders unless told otherwise")
      .def_property(
          "principal_point", [](Camera& c) { return c.principal_point(); },
          [](Camera& c, const Eigen::Vector2d& p) { c.set_principal_point(p.x(), p.y()); },
          "(cx, cy) in pixels; (W/2, H/2) unless moved (an off-axis camera)")
      .def_property("shadows", &Camera::shadows, &Camera::set_shadows,
                    "whether the rgb pass draws the shadows of lights with a shadow_quality "
                    "above 0 (directional and spot); ground-truth passes never change")
      .def_property("antialiasing", &Camera::antialiasing, &Camera::set_antialiasing,
                    "the rgb pass's antialiasing at edges and contrasts: 1 is off, 2 blends a "
                    "pixel's centre (1/2) with its four corners (1/8 each), 3 and 4 average a "
                    "k x k grid of samples; ground-truth passes stay one exact sample per pixel "
                    "centre")
      .def_property("looks", &Camera::looks, &Camera::set_looks,
                    "whether the rgb pass gives volumes ambient occlusion from their occupancy, "
                    "a world-fixed bone texture (the CT intensity where the volume has one) and "
                    "wet specular highlights; ground-truth passes never change");
}

void define_volume_object(py::class_<Volume, Object, std::shared_ptr<Volume>>& volume) {
  volume.def_property_readonly("data", &Volume::data)
      .def_property_readonly(
          "labels",
          [](Volume& v) {
            const py::object data = py::cast(v.data());
            return py::object(data.attr("labels"));  // an accessor would outlive `data`
          },
          "the data's label grid view (see VolumeData.labels)")
      .def_property("iso", &Volume::iso, &Volume::set_iso, "iso level of the smoothed occupancy")
      .def_property_readonly("quality", &Volume::quality)
      .def_property_readonly("optical_density", &Volume::optical_density)
      .def_property_readonly("specular", &Volume::specular, "Phong specular factor, 0..1")
      .def_property_readonly("shininess", &Volume::shininess, "Phong exponent")
      .def_property("empty_space_skipping", &Volume::empty_space_skipping,
                    &Volume::set_empty_space_skipping,
                    "rays skip empty bricks (off: every half voxel, the naive baseline)")
      .def_property_readonly("world_from_voxel", &Volume::world_from_voxel,
                             "4x4: voxel (i, j, k)'s centre is this times (i, j, k, 1)")
      .def("world_to_voxel", &Volume::world_to_voxel, py::arg("point"),
           "fractional voxel indices (centres at integers) of a world point")
      .def("voxel_to_world", &Volume::voxel_to_world, py::arg("ijk"),
           "the world point of fractional voxel indices")
      .def(
          "remove_sphere",
          [](Volume& v, const Vec3& c, double r, bool only_removable) {
            py::gil_scoped_release release;
            auto lock = v.world().lock_state();  // never while the world steps or renders
            return v.remove_sphere(c, r, only_removable);
          },
          py::arg("center"), py::arg("radius"), py::arg("only_removable") = true,
          "clears voxels within radius of a world-frame centre; returns how many")
      .def(
          "raycast",
          [](Volume& v, const Vec3& origin, const Vec3& direction) -> py::object {
            VolumeHit h;
            {
              // Under the world's lock: a drill may be editing the labels, and the ray cast
              // brings the volume's smoothed field up to date with those edits.
              py::gil_scoped_release release;
              auto lock = v.world().lock_state_for_copy();
              h = v.raycast(origin, direction);
            }
            return hit_dict(h);
          },
          py::arg("origin"), py::arg("direction"),
          "first iso-surface hit of a world-frame ray: dict(distance, position, normal, label) "
          "or None (under the world's lock: a real-time loop waits for it)")
      .def(
          "mark_dirty",
          [](Volume& v, std::optional<std::array<int, 3>> lo,
             std::optional<std::array<int, 3>> hi) {
            const VoxelBox box = box_from(lo, hi, *v.data());
            py::gil_scoped_release release;
            auto lock = v.world().lock_state();
            v.data()->mark_dirty(box);
          },
          py::arg("lo") = py::none(), py::arg("hi") = py::none(),
          "declares voxels [lo, hi) (default: all) changed through the labels view")
      .def(
          "reset",
          [](Volume& v) {
            py::gil_scoped_release release;
            auto lock = v.world().lock_state();
            v.data()->reset();
          },
          "restores the data's labels as loaded (or last committed)")
      .def_property_readonly(
          "last_upload",
          [](Volume& v) {
            const VolumeUploadStats s = last_volume_upload(v);
            py::dict d;
            d["rendered"] = s.rendered;
            d["full"] = s.full;
            d["voxels"] = s.voxels;
            d["seconds"] = s.seconds;
            return d;
          },
          "what the last render sent to the GPU: rendered, full, voxels, seconds");
}

void define_light(py::class_<Light, Object, std::shared_ptr<Light>>& light) {
  light.def_property_readonly("type", [](Light& l) { return light_type_name(l.type()); })
      .def_property_readonly("direction", &Light::direction)
      .def_property_readonly("color", &Light::color)
      .def_property_readonly("intensity", &Light::intensity)
      .def_property("shadow_quality", &Light::shadow_quality, &Light::set_shadow_quality,
                    "AMBF's `shadow quality`: 0 casts no shadow, 1..5 shadow maps of 256 to "
                    "4096 texels a side (directional and spot lights)");
}

void define_state_lock(py::module_& m) {
  bound<StateLock>(m, "_StateLock")
      .def(
          "__enter__", [](StateLock& s) { s.lock = lock_holding_gil(*s.world); },
          "Takes the world's state lock (waiting with the GIL released; the GIL is never "
          "waited for while the lock is held).")
      .def(
          "__exit__",
          [](StateLock& s, py::args) {
            if (s.lock.owns_lock()) s.lock.unlock();
            return false;
          },
          "Gives the lock back.");
}

// ---- The physical objects: RigidBody, Joint, SoftBody, ProximitySensor, ConstraintActuator.

using BodyClass = py::class_<RigidBody, Object, std::shared_ptr<RigidBody>>;
using JointClass = py::class_<Joint, Object, std::shared_ptr<Joint>>;
using SoftClass = py::class_<SoftBody, Object, std::shared_ptr<SoftBody>>;
using SensorClass = py::class_<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>;
using ActuatorClass = py::class_<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>;

py::dict controller_dict(const JointController& c) {
  py::dict d;
  d["p"] = c.p;
  d["i"] = c.i;
  d["d"] = c.d;
  d["output"] = control_output_name(c.output);
  return d;
}

// A read-only (rows, 3) NumPy view of `data`, kept alive by `owner`.
template <typename T>
py::array rows_view(py::object owner, const T* data, std::size_t rows) {
  const auto s = static_cast<py::ssize_t>(sizeof(T));
  return readonly(py::array(py::dtype::of<T>(), {static_cast<py::ssize_t>(rows), py::ssize_t(3)},
                            {3 * s, s}, data, owner));
}

py::array_t<double> rows_copy(const std::vector<double>& xyz) {
  py::array_t<double> out({static_cast<py::ssize_t>(xyz.size() / 3), py::ssize_t(3)});
  std::copy(xyz.begin(), xyz.end(), out.mutable_data());
  return out;
}

// A node index list: ints in range (OutOfRange otherwise).
std::vector<int> node_list(const SoftBody& s, const std::vector<int>& nodes) {
  const int count = static_cast<int>(s.node_count());
  for (int n : nodes) {
    if (n < 0 || n >= count) {
      throw OutOfRange("soft body '" + s.name() + "' has nodes 0.." + std::to_string(count - 1) +
                       ", not " + std::to_string(n));
    }
  }
  return nodes;
}

// Each ray's start or end, (N, 3), world frame.
py::array_t<double> ray_points(const ProximitySensor& s,
                               Vec3 (ProximitySensor::*point)(int) const) {
  std::vector<double> xyz;
  for (int i = 0; i < static_cast<int>(s.ray_count()); ++i) {
    const Vec3 p = (s.*point)(i);
    xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  }
  return rows_copy(xyz);
}

py::dict config_dict(const SoftBodyConfig& c) {
  py::dict d;
  d["kLST"] = c.linear_stiffness;
  d["kAST"] = c.area_stiffness;
  d["kVST"] = c.volume_stiffness;
  d["kVCF"] = c.velocity_correction;
  d["kDP"] = c.damping;
  d["kDG"] = c.drag;
  d["kLF"] = c.lift;
  d["kPR"] = c.pressure;
  d["kVC"] = c.volume_conservation;
  d["kDF"] = c.dynamic_friction;
  d["kMT"] = c.pose_matching ? py::cast(*c.pose_matching) : py::none();
  d["kCHR"] = c.rigid_hardness;
  d["kKHR"] = c.kinetic_hardness;
  d["kSHR"] = c.soft_hardness;
  d["kAHR"] = c.anchor_hardness;
  d["kSRHR_CL"] = c.cluster_rigid_hardness;
  d["kSKHR_CL"] = c.cluster_kinetic_hardness;
  d["kSSHR_CL"] = c.cluster_soft_hardness;
  d["kSR_SPLT_CL"] = c.cluster_rigid_impulse_split;
  d["kSK_SPLT_CL"] = c.cluster_kinetic_impulse_split;
  d["kSS_SPLT_CL"] = c.cluster_soft_impulse_split;
  d["maxvolume"] = c.max_volume;
  d["timescale"] = c.time_scale;
  d["viterations"] = c.velocity_iterations;
  d["piterations"] = c.position_iterations;
  d["diterations"] = c.drift_iterations;
  d["citerations"] = c.cluster_iterations;
  d["flags"] = c.collision_flags;
  d["bending constraint"] = c.bending_constraint ? py::cast(*c.bending_constraint) : py::none();
  d["clusters"] = c.clusters ? py::cast(*c.clusters) : py::none();
  d["fixed nodes"] = c.fixed_nodes;
  return d;
}

py::object hit_object(const SensorHit& h) {
  if (h.body != nullptr) return py::cast(handle(h.body));
  if (h.soft_body != nullptr) return py::cast(handle(h.soft_body));
  return py::none();
}

py::dict hit_to_dict(const SensorHit& h) {
  py::dict d;
  d["triggered"] = h.triggered;
  d["distance"] = h.distance;
  d["fraction"] = h.fraction;
  d["point"] = Vec3(h.point);
  d["normal"] = Vec3(h.normal);
  d["body"] = hit_object(h);
  d["node"] = h.soft_body_node >= 0 ? py::cast(h.soft_body_node) : py::none();
  return d;
}

void define_body(BodyClass& body) {
  body.def_property_readonly("shape", [](RigidBody& b) { return shape_kind_name(b.shape().kind); })
      .def_property_readonly("mass", &RigidBody::mass)
      .def_property_readonly("size", [](RigidBody& b) { return Vec3(b.shape().size); })
      .def_property_readonly("radius", [](RigidBody& b) { return b.shape().radius; })
      .def_property_readonly("height", [](RigidBody& b) { return b.shape().height; })
      .def_property_readonly("mesh", [](RigidBody& b) { return b.shape().mesh; })
      .def_property(
          "color", [](RigidBody& b) { return b.material().color; },
          [](RigidBody& b, const py::object& c) {
            Material m = b.material();
            m.color = to_option(c).rgba("color");
            b.set_material(m);
          },
          "RGBA in 0..1")
      .def_property(
          "shader", [](RigidBody& b) { return from_shader(b.material().shader); },
          [](RigidBody& b, const py::object& v) {
            Material m = b.material();
            m.shader = to_shader(v, "shader");
            b.set_material(m);
          },
          "the body's own shader (AMBF's body `shaders`): None (its model's), 'builtin' (the "
          "engine's own), or (vertex_path, fragment_path); it colours the rgb image only")
      .def_property_readonly("dynamic", &RigidBody::is_dynamic,
                             "moved by physics (mass > 0 and not kinematic)")
      .def_property(
          "kinematic", [](RigidBody& b) { return b.dynamics().kinematic; },
          &RigidBody::set_kinematic, "moved only by setting its pose")
      .def_property("linear_velocity", &RigidBody::linear_velocity, &RigidBody::set_linear_velocity,
                    "of the body origin, world frame, m/s")
      .def_property("angular_velocity", &RigidBody::angular_velocity,
                    &RigidBody::set_angular_velocity, "world frame, rad/s")
      .def_property(
          "force", [](RigidBody& b) { return Vec3(b.force()); }, &RigidBody::set_force,
          "N at the centre of mass, world frame, applied every step until changed")
      .def_property(
          "torque", [](RigidBody& b) { return Vec3(b.torque()); }, &RigidBody::set_torque,
          "N m, world frame, applied every step until changed")
      .def_property_readonly("inertia", &RigidBody::inertia,
                             "principal moments about the centre of mass, kg m^2")
      .def_property_readonly(
          "inertial_offset", [](RigidBody& b) { return Mat4(b.inertial_offset().matrix()); },
          "the centre-of-mass frame in the body frame")
      .def_property_readonly("center_of_mass", &RigidBody::center_of_mass, "world frame")
      .def_property(
          "friction", [](RigidBody& b) { return b.dynamics().static_friction; },
          [](RigidBody& b, double f) { b.set_friction(f, b.dynamics().rolling_friction); })
      .def_property(
          "rolling_friction", [](RigidBody& b) { return b.dynamics().rolling_friction; },
          [](RigidBody& b, double f) { b.set_friction(b.dynamics().static_friction, f); })
      .def_property(
          "restitution", [](RigidBody& b) { return b.dynamics().restitution; },
          &RigidBody::set_restitution)
      .def_property(
          "damping",
          [](RigidBody& b) {
            return py::make_tuple(b.dynamics().linear_damping, b.dynamics().angular_damping);
          },
          [](RigidBody& b, std::pair<double, double> d) { b.set_damping(d.first, d.second); },
          "(linear, angular), 0..1")
      .def_property_readonly(
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
              out.append(py::make_tuple(shape_kind_name(shape.kind), Mat4(pose)));
            }
            return out;
          },
          "the primitive collision parts as (shape, 4x4 pose in the body frame)")
      .def_property_readonly("is_ghost", &is_ghost, "a ghost object (World.add_ghost)")
      .def_property_readonly(
          "overlapping",
          [](RigidBody& b) {
            py::list out;
            for (Object* o : ghost_overlaps(b)) out.append(handle(o, b.world()));
            return out;
          },
          "a ghost's overlapping bodies after the last step, in creation order: rigid bodies "
          "(Bullet's narrow phase) and soft bodies with a node inside its convex parts; "
          "ValueError for a body that is not a ghost");
}

void define_joint(JointClass& joint) {
  joint.def_property_readonly("type", [](Joint& j) { return joint_type_name(j.type()); })
      .def_property_readonly("parent", [](Joint& j) { return handle(&j.parent(), j.world()); })
      .def_property_readonly("child", [](Joint& j) { return handle(&j.child(), j.world()); })
      .def_property_readonly("position", &Joint::position,
                             "rad or m; 0 where the parent's and child's joint frames coincide")
      .def_property_readonly("velocity", &Joint::velocity, "rad/s or m/s")
      .def_property_readonly("effort", &Joint::effort,
                             "effort applied in the last step (controller or command)")
      .def_property_readonly("passive", [](Joint& j) { return j.spec().passive; })
      .def_property_readonly("command",
                             [](Joint& j) {
                               switch (j.command()) {
                                 case Joint::Command::kPosition:
                                   return "position";
                                 case Joint::Command::kVelocity:
                                   return "velocity";
                                 case Joint::Command::kEffort:
                                   return "effort";
                                 case Joint::Command::kNone:
                                   break;
                               }
                               return "none";
                             })
      .def_property_readonly("command_value", &Joint::command_value)
      .def("set_position", &Joint::set_position, py::arg("target"),
           "drive to this position with the joint's controller")
      .def("set_velocity", &Joint::set_velocity, py::arg("target"),
           "drive at this velocity with the joint's motor")
      .def("set_effort", &Joint::set_effort, py::arg("effort"), "apply this effort every step")
      .def("release", &Joint::release, "stop commanding the joint")
      .def_property(
          "limits", [](Joint& j) { return py::make_tuple(j.spec().lower, j.spec().upper); },
          [](Joint& j, std::pair<std::optional<double>, std::optional<double>> l) {
            j.set_limits(l.first, l.second);
          },
          "(lower, upper), None where unlimited")
      .def_property(
          "damping", [](Joint& j) { return j.spec().damping; }, &Joint::set_damping)
      .def_property(
          "controller", [](Joint& j) { return controller_dict(j.spec().controller); },
          [](Joint& j, const py::dict& d) {
            JointController c = j.spec().controller;
            joint_controller_options().apply(c, to_options(d));
            j.set_controller(c);
          },
          "{p, i, d, output}; output 'effort' or 'velocity'; assigning updates the keys given")
      .def_property(
          "six_dof",
          [](Joint& j) -> py::object {
            const std::optional<SixDofAxes> a = six_dof_axes(j);
            if (!a) return py::none();
            py::dict d;
            d["lower"] = std::vector<std::optional<double>>(a->lower.begin(), a->lower.end());
            d["upper"] = std::vector<std::optional<double>>(a->upper.begin(), a->upper.end());
            d["stiffness"] = a->stiffness;
            d["damping"] = a->damping;
            d["equilibrium"] = a->equilibrium;
            return std::move(d);
          },
          [](Joint& j, const py::dict& d) {
            SixDofAxes a = six_dof_axes(j).value_or(SixDofAxes{});
            six_dof_options().apply(a, to_options(d));
            set_six_dof_axes(j, a);
          },
          "a six dof (spring) joint's per-axis settings {lower, upper, stiffness, damping, "
          "equilibrium}, 6 values each (x, y, z translation, then x, y, z rotation; a limit "
          "None or lower > upper: free); None before any were set; assigning updates the keys "
          "given")
      .def_property_readonly(
          "six_dof_coordinates", [](Joint& j) { return six_dof_coordinates(j); },
          "a six dof (spring) joint's six coordinates now (m, rad)")
      .def("set_cone_twist_limits", &set_cone_twist_limits, py::arg("twist"), py::arg("swing_y"),
           py::arg("swing_z"), "a cone twist joint's twist (about its axis) and swing spans, rad")
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
            const Vec3 a = j.parent().pose() * j.spec().parent_pivot;
            const Vec3 b = j.child().pose() * j.spec().child_pivot;
            return py::make_tuple(a, b);
          },
          "the pivot on the parent and on the child, world frame: the joint holds them "
          "together");
}

void define_soft_body(SoftClass& soft) {
  soft.def_property_readonly("mesh", [](SoftBody& s) { return s.spec().mesh; })
      .def_property_readonly("mass", &SoftBody::mass, "kg, shared evenly by the nodes")
      .def_property_readonly(
          "margin", [](SoftBody& s) { return s.spec().margin; }, "collision margin, m")
      .def_property_readonly(
          "config", [](SoftBody& s) { return config_dict(s.spec().config); },
          "the AMBF config coefficients it was created with (a copy)")
      .def_property_readonly("node_count", &SoftBody::node_count)
      .def_property_readonly(
          "nodes",
          [](py::object self) {
            const SoftBody& s = self.cast<const SoftBody&>();
            return rows_view(self, s.node_positions().data(), s.node_count());
          },
          "(N, 3) float64 node positions, world frame: a read-only view refreshed by every step "
          "(node i is the mesh's i-th distinct vertex)")
      .def_property_readonly(
          "triangles",
          [](py::object self) {
            const SoftBody& s = self.cast<const SoftBody&>();
            return rows_view(self, s.triangles().data(), s.triangles().size() / 3);
          },
          "(M, 3) uint32 node indices of the faces (read-only view)")
      .def_property_readonly(
          "node_velocities", [](SoftBody& s) { return rows_copy(s.node_velocities()); },
          "(N, 3) float64 node velocities, world frame, m/s (a copy)")
      .def(
          "set_node_positions",
          [](SoftBody& s, const std::vector<int>& nodes, const Eigen::MatrixX3d& positions) {
            const std::vector<int> list = node_list(s, nodes);
            if (static_cast<Eigen::Index>(list.size()) != positions.rows()) {
              throw ArgumentError("set_node_positions: " + std::to_string(list.size()) +
                                  " nodes but " + std::to_string(positions.rows()) + " positions");
            }
            for (std::size_t i = 0; i < list.size(); ++i) {
              s.set_node_position(list[i], positions.row(static_cast<Eigen::Index>(i)));
            }
          },
          py::arg("nodes"), py::arg("positions"),
          "Moves nodes (indices) to positions ((K, 3), world frame) at once.")
      .def(
          "fix_nodes",
          [](SoftBody& s, const std::vector<int>& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, true);
          },
          py::arg("nodes"), "Pins nodes (indices) where they are.")
      .def(
          "release_nodes",
          [](SoftBody& s, const std::vector<int>& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, false);
          },
          py::arg("nodes"), "Lets pinned nodes move again.")
      .def_property_readonly("fixed_nodes", &SoftBody::fixed_nodes, "pinned node indices")
      .def_property(
          "color", [](SoftBody& s) { return s.material().color; },
          [](SoftBody& s, const py::object& c) {
            Material mat = s.material();
            mat.color = to_option(c).rgba("color");
            s.set_material(mat);
          },
          "RGBA in 0..1")
      .def_property(
          "shader", [](SoftBody& s) { return from_shader(s.material().shader); },
          [](SoftBody& s, const py::object& v) {
            Material mat = s.material();
            mat.shader = to_shader(v, "shader");
            s.set_material(mat);
          },
          "its own shader: None (its model's), 'builtin', or (vertex_path, fragment_path)");
}

void define_sensor(SensorClass& sensor) {
  sensor.def_property_readonly("parent", [](ProximitySensor& s) { return handle(&s.parent()); })
      .def_property_readonly(
          "location", [](ProximitySensor& s) { return Mat4(s.spec().location); },
          "4x4 sensor frame in the parent's frame")
      .def_property("range", &ProximitySensor::range, &ProximitySensor::set_range,
                    "m each ray reaches (per unit of its direction)")
      .def_property_readonly("ray_count", &ProximitySensor::ray_count)
      .def_property_readonly("triggered", &ProximitySensor::triggered, "whether any ray hits")
      .def_property_readonly(
          "hits",
          [](ProximitySensor& s) {
            py::list out;
            for (const SensorHit& h : s.hits()) out.append(hit_to_dict(h));
            return out;
          },
          "per ray: dict(triggered, distance (m from the ray's start; its length on a miss), "
          "fraction, point, normal (world), body (RigidBody, SoftBody or None), node (soft "
          "body's nearest node or None))")
      .def_property_readonly(
          "distances",
          [](ProximitySensor& s) {
            py::array_t<double> out(static_cast<py::ssize_t>(s.ray_count()));
            for (std::size_t i = 0; i < s.ray_count(); ++i) {
              out.mutable_at(i) = s.hits()[i].distance;
            }
            return out;
          },
          "(N,) m from each ray's start to its hit (its length on a miss)")
      .def_property_readonly(
          "triggered_rays",
          [](ProximitySensor& s) {
            py::array_t<bool> out(static_cast<py::ssize_t>(s.ray_count()));
            for (std::size_t i = 0; i < s.ray_count(); ++i) {
              out.mutable_at(i) = s.hits()[i].triggered;
            }
            return out;
          },
          "(N,) bool, whether each ray hits")
      .def_property_readonly(
          "ray_starts",
          [](ProximitySensor& s) { return ray_points(s, &ProximitySensor::ray_start); },
          "(N, 3) world frame")
      .def_property_readonly(
          "ray_ends", [](ProximitySensor& s) { return ray_points(s, &ProximitySensor::ray_end); },
          "(N, 3) world frame")
      .def("update", &ProximitySensor::update,
           "Casts the rays now (the world does it after every physics step).");
}

void define_actuator(ActuatorClass& actuator) {
  actuator
      .def_property_readonly("parent", [](ConstraintActuator& a) { return handle(&a.parent()); })
      .def_property_readonly(
          "location", [](ConstraintActuator& a) { return Mat4(a.location().matrix()); },
          "4x4 actuator frame in the parent's frame")
      .def_property_readonly("max_impulse",
                             [](ConstraintActuator& a) { return a.spec().max_impulse; })
      .def_property_readonly("tau", [](ConstraintActuator& a) { return a.spec().tau; })
      .def_property_readonly(
          "hold", [](ConstraintActuator& a) { return actuator_hold_name(a.spec().hold); })
      .def(
          "actuate",
          [](ConstraintActuator& a, RigidBody& body, const py::object& offset) {
            if (offset.is_none()) {
              a.actuate(body);
              return;
            }
            const py::array arr = py::array::ensure(offset);
            if (arr && arr.ndim() == 2) {
              a.actuate(body, checked_pose(offset.cast<Mat4>(), a, "offset"));
            } else {
              Eigen::Isometry3d o = Eigen::Isometry3d::Identity();
              o.translation() = to_option(offset).vector3("offset");
              a.actuate(body, o);
            }
          },
          py::arg("body"), py::arg("offset") = py::none(),
          "Holds body: where it is now, or with the actuator at offset in the body's frame (a "
          "point, or a 4x4 frame), pulling it there. A body already held stays held.")
      .def("deactuate", &ConstraintActuator::deactuate, "Releases the body held.")
      .def("is_actuated", &ConstraintActuator::is_actuated, "Whether a body is held.")
      .def_property_readonly(
          "actuated_body",
          [](ConstraintActuator& a) -> py::object {
            return a.actuated_body() ? py::cast(handle(a.actuated_body())) : py::none();
          },
          "the body held, or None");
}

}  // namespace

py::object state_lock(World& world) { return py::cast(StateLock{handle(&world, world), {}}); }

// The world's state lock for a thread holding the GIL, taken so that it never waits for the GIL
// while holding the lock: another Python thread may keep the GIL for a switch interval (5 ms),
// and a real-time loop waiting for the lock would wait as long. The lock is only taken while
// the GIL is held, and waited for, while busy, with the GIL released.
void refuse_during_loop(const World& world, const char* call) {
  if (world.realtime()) {
    throw StateError(std::string(call) + ": a RealTimeLoop is stepping world '" + world.name() +
                     "'; two steppers would interleave their steps. Stop the loop (loop.stop()) "
                     "first, or leave the stepping to it");
  }
}

std::unique_lock<StateMutex> lock_holding_gil(World& world) {
  std::unique_lock<StateMutex> lock(world.state_mutex(), std::defer_lock);
  while (!lock.try_lock()) {
    py::gil_scoped_release release;
    std::lock_guard<StateMutex> wait(world.state_mutex());
  }
  return lock;
}

void declare_scene(py::module_& m) {
  declare_enum<LightSpec::Type>(m, "LightType", "How a light shines.",
                                {{"directional", LightSpec::Type::kDirectional},
                                 {"point", LightSpec::Type::kPoint},
                                 {"spot", LightSpec::Type::kSpot}},
                                &parse_light_type);
  py::class_<Simulator, std::shared_ptr<Simulator>>(
      m, "Simulator", "The top of the hierarchy Simulator > World > Model > Object.");
  py::class_<World, std::shared_ptr<World>>(
      m, "World", "The scene (models and their objects) and the simulation clock.");
  py::class_<Model, std::shared_ptr<Model>>(
      m, "Model", "A group of objects; names are unique across the whole world.");
  py::class_<Object, std::shared_ptr<Object>>(m, "Object",
                                              "Anything in a world with a unique name.");
  py::class_<Camera, Object, std::shared_ptr<Camera>>(
      m, "Camera", "A pinhole camera; pose is world from camera in the OpenCV frame.");
  py::class_<Light, Object, std::shared_ptr<Light>>(
      m, "Light", "A directional, point or spot light shining along its +z axis.");
  py::class_<Volume, Object, std::shared_ptr<Volume>>(
      m, "Volume", "Segmented volume data placed in a world, rendered by ray casting.");
  declare_enum<Shape::Kind>(m, "ShapeKind", "A rigid body's geometry.",
                            {{"box", Shape::Kind::kBox},
                             {"sphere", Shape::Kind::kSphere},
                             {"cylinder", Shape::Kind::kCylinder},
                             {"capsule", Shape::Kind::kCapsule},
                             {"cone", Shape::Kind::kCone},
                             {"plane", Shape::Kind::kPlane},
                             {"mesh", Shape::Kind::kMesh},
                             {"none", Shape::Kind::kNone}},
                            &parse_shape_kind);
  declare_enum<Axis>(m, "Axis", "A body axis (cylinders, capsules and cones run along one).",
                     {{"x", Axis::kX}, {"y", Axis::kY}, {"z", Axis::kZ}}, &parse_axis);
  declare_enum<MeshCollision>(m, "MeshCollision",
                              "How a body's collision shape is made from a mesh.",
                              {{"concave", MeshCollision::kConcave},
                               {"convex_mesh", MeshCollision::kConvexMesh},
                               {"convex_hull", MeshCollision::kConvexHull},
                               {"point_cloud", MeshCollision::kPointCloud}},
                              &parse_mesh_collision);
  declare_enum<JointType>(m, "JointType", "How a joint lets its child move.",
                          {{"revolute", JointType::kRevolute},
                           {"prismatic", JointType::kPrismatic},
                           {"fixed", JointType::kFixed},
                           {"linear_spring", JointType::kLinearSpring},
                           {"torsion_spring", JointType::kTorsionSpring},
                           {"p2p", JointType::kP2P},
                           {"cone_twist", JointType::kConeTwist},
                           {"six_dof", JointType::kSixDof},
                           {"six_dof_spring", JointType::kSixDofSpring}},
                          &parse_joint_type);
  declare_enum<ControlOutput>(
      m, "ControlOutput", "What a joint controller drives.",
      {{"effort", ControlOutput::kEffort}, {"velocity", ControlOutput::kVelocity}},
      &parse_control_output);
  declare_enum<ActuatorHold>(m, "ActuatorHold", "How a constraint actuator holds a body.",
                             {{"fixed", ActuatorHold::kFixed}, {"point", ActuatorHold::kPoint}},
                             &parse_actuator_hold);
  BodyClass(m, "RigidBody", "A rigid body: a shape with mass and a material.");
  JointClass(m, "Joint", "A joint between two bodies, with a controller and limits.");
  SoftClass(m, "SoftBody",
            "A deformable body: Bullet nodes at a mesh's vertices, links along its edges.");
  SensorClass(m, "ProximitySensor", "Rays fixed to a body reporting the nearest body along each.");
  ActuatorClass(m, "ConstraintActuator", "Holds a body to its parent body on request (a grasp).");
  py::class_<StateLock>(m, "_StateLock", "The world's state lock, held by a `with` block.");
}

void define_scene(py::module_& m) {
  auto simulator = bound<Simulator, std::shared_ptr<Simulator>>(m, "Simulator");
  define_simulator(simulator);
  auto world = bound<World, std::shared_ptr<World>>(m, "World");
  define_world(world);
  auto model = bound<Model, std::shared_ptr<Model>>(m, "Model");
  define_model(model);
  auto object = bound<Object, std::shared_ptr<Object>>(m, "Object");
  define_object(object);
  auto camera = bound<Camera, Object, std::shared_ptr<Camera>>(m, "Camera");
  define_camera(camera);
  m.attr("MAX_ANTIALIASING") = kMaxAntialiasing;
  auto light = bound<Light, Object, std::shared_ptr<Light>>(m, "Light");
  define_light(light);
  auto volume = bound<Volume, Object, std::shared_ptr<Volume>>(m, "Volume");
  define_volume_object(volume);
  auto body = bound<RigidBody, Object, std::shared_ptr<RigidBody>>(m, "RigidBody");
  define_body(body);
  auto joint = bound<Joint, Object, std::shared_ptr<Joint>>(m, "Joint");
  define_joint(joint);
  auto soft = bound<SoftBody, Object, std::shared_ptr<SoftBody>>(m, "SoftBody");
  define_soft_body(soft);
  auto sensor =
      bound<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>(m, "ProximitySensor");
  define_sensor(sensor);
  auto actuator = bound<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>(
      m, "ConstraintActuator");
  define_actuator(actuator);
  define_state_lock(m);
}

}  // namespace ambfplus::bindings
