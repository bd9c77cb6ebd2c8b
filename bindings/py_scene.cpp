#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>
#include <sstream>

#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/haptics/device.h"
#include "ambfplus/render/render_stats.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/simulator.h"
#include "bindings.h"

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

template <typename T>
py::list to_python_list(const std::vector<T*>& objects) {
  py::list out;
  for (T* o : objects) out.append(to_python(o));
  return out;
}

std::array<float, 4> rgba(const std::vector<double>& c, const char* what) {
  if (c.size() != 3 && c.size() != 4) {
    throw py::value_error(std::string(what) + " must be (r, g, b) or (r, g, b, a) in 0..1");
  }
  std::array<float, 4> out{0, 0, 0, 1};
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!(c[i] >= 0.0 && c[i] <= 1.0)) {
      throw py::value_error(std::string(what) + " components must be in 0..1");
    }
    out[i] = static_cast<float>(c[i]);
  }
  return out;
}

std::array<float, 3> rgb(const std::vector<double>& c, const char* what) {
  if (c.size() != 3) throw py::value_error(std::string(what) + " must be (r, g, b)");
  const auto four = rgba(c, what);
  return {four[0], four[1], four[2]};
}

// Rejects a dimension given for a shape it does not apply to.
void reject(bool given, const char* key, Shape::Kind kind) {
  if (given) {
    throw py::value_error(std::string(key) + " does not apply to a " + shape_kind_name(kind) +
                          " body");
  }
}

RigidBodySpec body_spec(const std::string& name, const std::string& shape, std::optional<Vec3> size,
                        std::optional<double> radius, std::optional<double> height,
                        std::optional<std::string> mesh, double scale, std::optional<Mat4> pose,
                        double mass, std::optional<std::vector<double>> color,
                        std::optional<double> specular, std::optional<double> shininess,
                        const py::kwargs& physics) {
  RigidBodySpec spec;
  spec.name = name;
  spec.shape.kind = parse_shape_kind(shape.empty() ? (mesh ? "mesh" : "box") : shape);
  const Shape::Kind kind = spec.shape.kind;
  const auto need = [&](bool given, const char* key) {
    if (!given) {
      throw py::value_error("body '" + name + "': a " + shape_kind_name(kind) + " needs " + key);
    }
  };
  switch (kind) {
    case Shape::Kind::kBox:
      need(size.has_value(), "size=(x, y, z)");
      reject(radius.has_value(), "radius", kind);
      reject(height.has_value(), "height", kind);
      spec.shape.size = *size;
      break;
    case Shape::Kind::kSphere:
      need(radius.has_value(), "radius");
      reject(size.has_value(), "size", kind);
      reject(height.has_value(), "height", kind);
      spec.shape.radius = *radius;
      break;
    case Shape::Kind::kCylinder:
    case Shape::Kind::kCapsule:
    case Shape::Kind::kCone:
      need(radius.has_value() && height.has_value(), "radius and height");
      reject(size.has_value(), "size", kind);
      spec.shape.radius = *radius;
      spec.shape.height = *height;
      break;
    case Shape::Kind::kPlane:
      reject(size.has_value(), "size", kind);
      reject(radius.has_value(), "radius", kind);
      reject(height.has_value(), "height", kind);
      break;
    case Shape::Kind::kNone:
      reject(size.has_value(), "size", kind);
      reject(radius.has_value(), "radius", kind);
      reject(height.has_value(), "height", kind);
      break;
    case Shape::Kind::kMesh:
      need(mesh.has_value(), "mesh='file'");
      reject(size.has_value(), "size", kind);
      reject(radius.has_value(), "radius", kind);
      reject(height.has_value(), "height", kind);
      spec.shape.mesh = *mesh;
      spec.shape.scale = scale;
      break;
  }
  if (kind != Shape::Kind::kMesh) {
    if (mesh) throw py::value_error("mesh= needs shape='mesh' (or no shape)");
    if (scale != 1.0) throw py::value_error("scale applies to mesh bodies only");
  }
  if (pose) spec.pose = *pose;
  spec.dynamics.mass = mass;
  if (color) spec.material.color = rgba(*color, "color");
  if (specular) spec.material.specular = static_cast<float>(*specular);
  if (shininess) spec.material.shininess = static_cast<float>(*shininess);
  apply_body_options(spec, physics);
  return spec;
}

RigidBody& add_body(Model& model, const RigidBodySpec& spec) {
  py::gil_scoped_release release;  // mesh files can take a while to read
  return model.add_body(spec);
}

Camera& add_camera(Model& model, const std::string& name, int width, int height, double fov_y,
                   double near, double far, std::optional<Mat4> pose,
                   const std::vector<double>& background) {
  CameraSpec spec;
  spec.name = name;
  spec.width = width;
  spec.height = height;
  spec.fov_y = fov_y;
  spec.near = near;
  spec.far = far;
  if (pose) spec.pose = *pose;
  spec.background = rgb(background, "background");
  return model.add_camera(spec);
}

Light& add_light(Model& model, const std::string& name, const std::string& type,
                 const Vec3& position, const Vec3& direction, const std::vector<double>& color,
                 double intensity, double spot_cutoff, double spot_exponent,
                 const Vec3& attenuation) {
  LightSpec spec;
  spec.name = name;
  spec.type = parse_light_type(type);
  spec.position = position;
  spec.direction = direction;
  spec.color = rgb(color, "color");
  spec.intensity = static_cast<float>(intensity);
  spec.spot_cutoff = static_cast<float>(spot_cutoff);
  spec.spot_exponent = static_cast<float>(spot_exponent);
  for (int i = 0; i < 3; ++i) spec.attenuation[i] = static_cast<float>(attenuation[i]);
  return model.add_light(spec);
}

// The add_* methods, shared by Model and World (which adds to its default model).
template <typename Class, typename GetModel>
void def_adders(Class& cls, GetModel get_model) {
  cls.def(
         "add_body",
         [get_model](typename Class::type& self, const std::string& name, const std::string& shape,
                     std::optional<Vec3> size, std::optional<double> radius,
                     std::optional<double> height, std::optional<std::string> mesh, double scale,
                     std::optional<Mat4> pose, double mass,
                     std::optional<std::vector<double>> color, std::optional<double> specular,
                     std::optional<double> shininess, const py::kwargs& physics) {
           Model& model = get_model(self);
           const RigidBodySpec spec = body_spec(name, shape, size, radius, height, mesh, scale,
                                                pose, mass, color, specular, shininess, physics);
           return handle(&add_body(model, spec), model.world());
         },
         py::arg("name"), py::arg("shape") = "", py::kw_only(), py::arg("size") = py::none(),
         py::arg("radius") = py::none(), py::arg("height") = py::none(),
         py::arg("mesh") = py::none(), py::arg("scale") = 1.0, py::arg("pose") = py::none(),
         py::arg("mass") = 1.0, py::arg("color") = py::none(), py::arg("specular") = py::none(),
         py::arg("shininess") = py::none(),
         "Adds a rigid body: shape is box (size = full extents), sphere (radius), cylinder, "
         "capsule or cone (radius, height along axis, z unless axis='x' or 'y'; a capsule's "
         "height includes its caps), plane (z = 0, infinite) or mesh (mesh = file, scale); pose "
         "is a 4x4 world-from-body matrix. Physics (mass > 0 moves under gravity; 0 is static): "
         "inertia, inertial_offset (4x4), friction, rolling_friction, restitution, "
         "linear_damping, angular_damping, kinematic, collision (False: none), collision_mesh, "
         "collision_type (concave, convex_mesh, convex_hull, point_cloud), collision_shapes "
         "([{shape, size/radius/height/axis, pose}]), margin, groups ([0..31]).")
      .def(
          "add_ghost",
          [get_model](typename Class::type& self, const std::string& name, const std::string& shape,
                      std::optional<Vec3> size, std::optional<double> radius,
                      std::optional<double> height, std::optional<std::string> mesh, double scale,
                      std::optional<Mat4> pose, std::optional<std::vector<double>> color,
                      bool visible, const py::kwargs& collision) {
            Model& model = get_model(self);
            RigidBodySpec spec = body_spec(name, shape, size, radius, height, mesh, scale, pose,
                                           0.0, color, std::nullopt, std::nullopt, collision);
            spec.material.visible = visible;
            RigidBody* ghost = nullptr;
            {
              py::gil_scoped_release release;
              ghost = &add_ghost(model, spec);
            }
            return handle(ghost, model.world());
          },
          py::arg("name"), py::arg("shape") = "", py::kw_only(), py::arg("size") = py::none(),
          py::arg("radius") = py::none(), py::arg("height") = py::none(),
          py::arg("mesh") = py::none(), py::arg("scale") = 1.0, py::arg("pose") = py::none(),
          py::arg("color") = py::none(), py::arg("visible") = true,
          "Adds a ghost object (AMBF's ghost objects): a shape as add_body takes it that "
          "touches nothing (no force, rays pass through) and reports, after every step, the "
          "bodies overlapping it (body.overlapping, Bullet's narrow phase). It moves by its pose "
          "or rides on a parent (attach_to). Collision keywords of add_body (collision_mesh, "
          "collision_type, collision_shapes, margin) shape what it tests.")
      .def(
          "add_joint",
          [get_model](typename Class::type& self, const std::string& name, RigidBody& parent,
                      RigidBody& child, const std::string& type, const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_joint(model, name, parent, child, type, kw), model.world());
          },
          py::arg("name"), py::arg("parent"), py::arg("child"), py::arg("type") = "revolute",
          "Adds a joint (revolute/hinge/continuous, prismatic/slider, fixed, spring, torsion "
          "spring, p2p, cone twist, six dof, six dof spring) between two bodies. Keywords: "
          "parent_pivot, parent_axis, child_pivot, child_axis (each body's frame), offset, "
          "child_offset, lower, upper, damping, stiffness, equilibrium, max_motor_impulse, erp, "
          "cfm, controller ({p, i, d, output}), passive, ignore_inter_collision.")
      .def(
          "add_camera",
          [get_model](typename Class::type& self, const std::string& name, int width, int height,
                      double fov_y, double near, double far, std::optional<Mat4> pose,
                      const std::vector<double>& background) {
            Model& model = get_model(self);
            return handle(
                &add_camera(model, name, width, height, fov_y, near, far, pose, background),
                model.world());
          },
          py::arg("name"), py::arg("width") = 640, py::arg("height") = 480, py::arg("fov_y") = 0.7,
          py::arg("near") = 0.1, py::arg("far") = 10.0, py::kw_only(), py::arg("pose") = py::none(),
          py::arg("background") = std::vector<double>{0.0, 0.0, 0.0},
          "Adds a pinhole camera (OpenCV frame: x right, y down, z forward); fov_y is the "
          "vertical field of view in radians, near and far the clipping distances in metres.")
      .def(
          "add_light",
          [get_model](typename Class::type& self, const std::string& name, const std::string& type,
                      const Vec3& position, const Vec3& direction, const std::vector<double>& color,
                      double intensity, double spot_cutoff, double spot_exponent,
                      const Vec3& attenuation) {
            Model& model = get_model(self);
            return handle(&add_light(model, name, type, position, direction, color, intensity,
                                     spot_cutoff, spot_exponent, attenuation),
                          model.world());
          },
          py::arg("name"), py::arg("type") = "directional", py::kw_only(),
          py::arg("position") = Vec3(0, 0, 0), py::arg("direction") = Vec3(0, 0, -1),
          py::arg("color") = std::vector<double>{1.0, 1.0, 1.0}, py::arg("intensity") = 1.0,
          py::arg("spot_cutoff") = 0.7, py::arg("spot_exponent") = 0.7,
          py::arg("attenuation") = Vec3(1, 0, 0),
          "Adds a directional, point or spot light shining along direction. A world without "
          "lights is lit by a headlight at each camera.")
      .def(
          "add_volume",
          [get_model](typename Class::type& self, const std::string& name,
                      std::shared_ptr<VolumeData> data, std::optional<Mat4> pose, double iso,
                      double quality, double optical_density, std::optional<float> specular,
                      std::optional<float> shininess) {
            Model& model = get_model(self);
            VolumeSpec spec;
            spec.name = name;
            spec.data = std::move(data);
            if (pose) spec.pose = *pose;
            spec.iso = iso;
            spec.quality = quality;
            spec.optical_density = optical_density;
            if (specular) spec.specular = *specular;
            if (shininess) spec.shininess = *shininess;
            return handle(&model.add_volume(spec), model.world());
          },
          py::arg("name"), py::arg("data"), py::kw_only(), py::arg("pose") = py::none(),
          py::arg("iso") = 0.5, py::arg("quality") = 0.5, py::arg("optical_density") = 1.0,
          py::arg("specular") = py::none(), py::arg("shininess") = py::none(),
          "Places volume data in the world; pose is world from the volume frame (centred on the "
          "grid). Several volumes may share one VolumeData. specular (0..1) and shininess (Phong "
          "exponent) set the surface's material (defaults 0.15 and 24).")
      .def(
          "add_drill",
          [get_model](typename Class::type& self, const std::string& name, Volume& volume,
                      const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_drill(model, name, volume, kw), model.world());
          },
          py::arg("name"), py::arg("volume"),
          "Adds a drill working on `volume`. Options: burr_diameters (m), burr (index), cursors, "
          "spacing, shaft_radii, stiffness (N/m), damping, max_force, soft_start, "
          "static_friction, dynamic_friction, removal ('physical' or 'compatible'), "
          "cutting_rate (m^3/(s N)), voxels_per_step, pose (initial goal, 4x4).")
      .def(
          "add_input_device",
          [get_model](typename Class::type& self, const std::string& name,
                      const std::shared_ptr<Device>& device, Drill& drill, const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_input_device(model, name, device, drill, kw), model.world());
          },
          py::arg("name"), py::arg("device"), py::arg("drill"),
          "Binds a device to a drill. Options: workspace_scale (world m per device m), reference "
          "(an object, e.g. a camera, whose axes device motion follows: x right, y up, z towards "
          "the viewer), drill_button (0), clutch_button (1), burr_button (-1: none), max_force "
          "(N), force_scale.")
      .def(
          "add_soft_body",
          [get_model](typename Class::type& self, const std::string& name,
                      const std::filesystem::path& mesh, const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_soft_body(model, name, mesh.string(), kw), model.world());
          },
          py::arg("name"), py::arg("mesh"),
          "Adds a soft body made from a mesh file (STL, OBJ, ...): nodes at its distinct "
          "vertices, links along its triangle edges. Keywords: scale, pose (4x4 world from the "
          "mesh frame), mass (kg, shared evenly), margin (collision margin, m), config (AMBF's "
          "config block as a dict: kLST, kAST, kVST, kVCF, kDP, kDG, kLF, kPR, kVC, kDF, kMT, "
          "kCHR, kKHR, kSHR, kAHR, cluster keys, viterations, piterations, diterations, "
          "citerations, flags, 'bending constraint', clusters, 'fixed nodes'), fixed_nodes, "
          "randomize_constraints, color, specular, shininess.")
      .def(
          "add_sensor",
          [get_model](typename Class::type& self, const std::string& name, RigidBody& parent,
                      const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_sensor(model, name, parent, kw), model.world());
          },
          py::arg("name"), py::arg("parent"),
          "Adds a proximity sensor fixed to parent, updated after every physics step. Keywords: "
          "location (4x4 in the parent's frame) or pose (4x4 world, now), range (m, 0.5), one "
          "ray by offset and direction (sensor frame, default +x from the origin), or rays "
          "([{offset, direction}]) or parametric ({resolution, horizontal angle, vertical "
          "angle, start offset}); a ray reaches offset + direction * range. visible, "
          "visible_size.")
      .def(
          "add_actuator",
          [get_model](typename Class::type& self, const std::string& name, RigidBody& parent,
                      const py::kwargs& kw) {
            Model& model = get_model(self);
            return handle(&add_actuator(model, name, parent, kw), model.world());
          },
          py::arg("name"), py::arg("parent"),
          "Adds a constraint actuator on parent that holds bodies on request. Keywords: "
          "location (4x4 in the parent's frame) or pose (4x4 world, now), hold ('fixed': the "
          "body keeps its pose relative to the actuator, or 'point': only the point is held), "
          "max_impulse (N s per step, point hold), tau (point hold), visible, visible_size.");
}

std::string repr_object(const Object& o) {
  std::ostringstream s;
  s << "<" << object_kind_name(o.kind()) << " '" << o.name() << "' id=" << o.id() << ">";
  return s.str();
}

}  // namespace

void register_scene(py::module_& m) {
  py::class_<Simulator, std::shared_ptr<Simulator>> simulator(
      m, "Simulator", "The top of the hierarchy Simulator > World > Model > Object.");
  py::class_<World, std::shared_ptr<World>> world(
      m, "World", "The scene (models and their objects) and the simulation clock.");
  py::class_<Model, std::shared_ptr<Model>> model(
      m, "Model", "A group of objects; names are unique across the whole world.");
  py::class_<Object, std::shared_ptr<Object>> object(m, "Object",
                                                     "Anything in a world with a unique name.");
  py::class_<RigidBody, Object, std::shared_ptr<RigidBody>> body(
      m, "RigidBody", "A rigid body: a shape with mass and a material.");
  py::class_<Joint, Object, std::shared_ptr<Joint>> joint(
      m, "Joint", "A joint between two bodies, with a controller and limits.");
  py::class_<Camera, Object, std::shared_ptr<Camera>> camera(
      m, "Camera", "A pinhole camera; pose is world from camera in the OpenCV frame.");
  py::class_<Light, Object, std::shared_ptr<Light>> light(
      m, "Light", "A directional, point or spot light shining along its +z axis.");
  py::class_<Volume, Object, std::shared_ptr<Volume>> volume(
      m, "Volume", "Segmented volume data placed in a world, rendered by ray casting.");
  py::class_<Drill, Object, std::shared_ptr<Drill>> drill(
      m, "Drill", "A burr and shaft of finger-proxy cursors that drills a volume.");
  register_haptics(m, drill);
  py::class_<InputDevice, Object, std::shared_ptr<InputDevice>> input(
      m, "InputDevice",
      "A device bound to a drill: its motion moves the drill's goal (workspace scale, clutch, "
      "the reference's axes), its buttons turn and change the burr, the drill's force goes back; "
      "every reading is logged with its step.");
  register_devices(m, input);
  register_world_io(world);
  register_physics(m, body, joint);
  py::class_<SoftBody, Object, std::shared_ptr<SoftBody>> soft_body(
      m, "SoftBody",
      "A deformable body: Bullet nodes at a mesh's vertices, links along its edges.");
  py::class_<ProximitySensor, Object, std::shared_ptr<ProximitySensor>> sensor(
      m, "ProximitySensor", "Rays fixed to a body reporting the nearest body along each.");
  py::class_<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>> actuator(
      m, "ConstraintActuator", "Holds a body to its parent body on request (a grasp).");
  register_soft(m, soft_body, sensor, actuator);

  simulator
      .def(py::init([](double time_step, const std::string& world_name) {
             SimulatorOptions options;
             options.time_step = time_step;
             options.world_name = world_name;
             return Simulator::create(options);
           }),
           py::arg("time_step") = 0.001, py::arg("world_name") = "World")
      .def_property_readonly("world", [](Simulator& s) { return handle(&s.world(), s.world()); })
      .def(
          "step",
          [](Simulator& s, std::int64_t n) {
            py::gil_scoped_release release;
            s.step(n);
          },
          py::arg("n") = 1, "Advances the world by n fixed steps.");

  world
      .def(py::init([](double time_step, const std::string& name) {
             SimulatorOptions options;
             options.time_step = time_step;
             options.world_name = name;
             auto sim = Simulator::create(options);
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
            py::gil_scoped_release release;
            w.step(n);
          },
          py::arg("n") = 1, "Advances the clock by n fixed steps.")
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
          [](World& w, const std::string& name) { return handle(&w.add_model(name), w); },
          py::arg("name"))
      .def(
          "get",
          [](World& w, const std::string& name) {
            Object* o = w.find(name);
            if (o == nullptr) throw py::key_error("no object named '" + name + "' in the world");
            return to_python(o);
          },
          py::arg("name"), "The object with exactly this name; KeyError if there is none.")
      .def("__getitem__",
           [](World& w, const std::string& name) {
             Object* o = w.find(name);
             if (o == nullptr) throw py::key_error(name);
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
      .def_property("gravity", &World::gravity, &World::set_gravity, "m/s^2, world frame")
      .def_property(
          "shader", [](World& w) { return from_shader(w.shader()); },
          [](World& w, const py::object& v) { w.set_shader(to_shader(v, "shader")); },
          "the shader of bodies whose model and own material name none (AMBF's world "
          "`shaders`): None (the engine's own), 'builtin', or (vertex_path, fragment_path)")
      .def_property_readonly("joints",
                             [](World& w) { return to_python_list(w.objects_of_kind<Joint>()); })
      .def_property_readonly("drills",
                             [](World& w) { return to_python_list(w.objects_of_kind<Drill>()); })
      .def_property_readonly(
          "input_devices",
          [](World& w) { return to_python_list(w.objects_of_kind<InputDevice>()); })
      .def("lock", &state_lock,
           "A context manager holding the world's state lock: a real-time loop's steps and "
           "captures from other threads wait meanwhile.")
      .def(
          "load_volumes",
          [](World& w, const std::filesystem::path& path,
             std::optional<std::filesystem::path> labels) {
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
      .def("__repr__", [](World& w) {
        std::ostringstream s;
        s << "<World '" << w.name() << "' objects=" << w.objects().size()
          << " step=" << w.step_index() << ">";
        return s.str();
      });
  def_adders(world, [](World& w) -> Model& { return w.default_model(); });

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

  object.def_property_readonly("name", &Object::name)
      .def_property_readonly("id", &Object::id, "stable instance id (>= 1) used by segmentation")
      .def_property_readonly("kind", [](Object& o) { return object_kind_name(o.kind()); })
      .def_property_readonly("model", [](Object& o) { return handle(&o.model(), o.world()); })
      .def_property(
          "pose", [](Object& o) { return Mat4(o.pose().matrix()); },
          [](Object& o, const Mat4& m) { o.set_pose(checked_pose(m)); },
          "4x4 world-from-object rigid transform (a copy; assign to change it)")
      .def("__repr__", &repr_object);

  body.def_property_readonly("shape", [](RigidBody& b) { return shape_kind_name(b.shape().kind); })
      .def_property_readonly("mass", &RigidBody::mass)
      .def_property_readonly("size", [](RigidBody& b) { return Vec3(b.shape().size); })
      .def_property_readonly("radius", [](RigidBody& b) { return b.shape().radius; })
      .def_property_readonly("height", [](RigidBody& b) { return b.shape().height; })
      .def_property_readonly("mesh", [](RigidBody& b) { return b.shape().mesh; })
      .def_property(
          "color", [](RigidBody& b) { return b.material().color; },
          [](RigidBody& b, const std::vector<double>& c) {
            Material m = b.material();
            m.color = rgba(c, "color");
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
          "engine's own), or (vertex_path, fragment_path); it colours the rgb image only");

  camera.def_property_readonly("width", &Camera::width)
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
      .def_property_readonly("height", &Camera::height)
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
           "render ('rgb', 'depth', 'label', 'instance', 'voxel', 'segmentation'; default "
           "camera.passes), and "
           "only those. out=Frame refills that frame's images in place; out={'rgb': a, "
           "'depth': b, ...} renders into preallocated arrays. poses: object names (or True for "
           "all) whose world poses the frame records in frame.poses.")
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
          "(cx, cy) in pixels; (W/2, H/2) unless moved (an off-axis camera)");

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
      .def("voxel_to_world", &Volume::voxel_to_world, py::arg("ijk"))
      .def(
          "remove_sphere",
          [](Volume& v, const Vec3& c, double r, bool only_removable) {
            py::gil_scoped_release release;
            return v.remove_sphere(c, r, only_removable);
          },
          py::arg("center"), py::arg("radius"), py::arg("only_removable") = true,
          "clears voxels within radius of a world-frame centre; returns how many")
      .def(
          "raycast",
          [](Volume& v, const Vec3& origin, const Vec3& direction) -> py::object {
            VolumeHit h;
            {
              py::gil_scoped_release release;
              h = v.raycast(origin, direction);
            }
            return hit_dict(h);
          },
          py::arg("origin"), py::arg("direction"),
          "first iso-surface hit of a world-frame ray: dict(distance, position, normal, label) "
          "or None")
      .def(
          "mark_dirty",
          [](Volume& v, std::optional<std::array<int, 3>> lo,
             std::optional<std::array<int, 3>> hi) {
            v.data()->mark_dirty(box_from(lo, hi, *v.data()));
          },
          py::arg("lo") = py::none(), py::arg("hi") = py::none())
      .def("reset", [](Volume& v) { v.data()->reset(); })
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

  light.def_property_readonly("type", [](Light& l) { return light_type_name(l.type()); })
      .def_property_readonly("direction", &Light::direction)
      .def_property_readonly("color", &Light::color)
      .def_property_readonly("intensity", &Light::intensity);
}

}  // namespace ambfplus::bindings
