#pragma once

#include <pybind11/pybind11.h>

namespace ambfplus::bindings {

// One registration function per area, called once from module.cpp in dependency order.
void register_errors(pybind11::module_& m);
void register_io(pybind11::module_& m);
void register_render(pybind11::module_& m);
void register_capture(pybind11::module_& m);
void register_volume(pybind11::module_& m);
void register_scene(pybind11::module_& m);
void register_adf(pybind11::module_& m);
void register_plugin(pybind11::module_& m);

}  // namespace ambfplus::bindings

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "ambfplus/render/shader.h"
#include "ambfplus/scene/simulator.h"

namespace ambfplus {
class Camera;
class ConstraintActuator;
class Device;
class Drill;
class InputDevice;
class Joint;
class RigidBody;
struct RigidBodySpec;
class Model;
class Object;
class ProximitySensor;
class SoftBody;
class Volume;
class VolumeData;
struct VolumeHit;
struct VoxelBox;
}  // namespace ambfplus

namespace ambfplus::bindings {

/// Every handle given to Python shares ownership of the simulator, so no handle outlives the
/// objects it points into, whatever order Python drops them in.
template <typename T>
std::shared_ptr<T> handle(T* p, World& world) {
  return std::shared_ptr<T>(world.simulator().shared_from_this(), p);
}

/// ambfplus.PluginError, the Python class (set when the module is made).
PyObject* plugin_error_type();

/// An object as its most derived Python class (None for nullptr).
pybind11::object to_python(Object* o);

/// Camera.capture(out=None): renders with the GIL released. out may be None (a new Frame), a Frame
/// (refilled in place) or a dict of preallocated arrays {"rgb": ..., "depth": ...}.
pybind11::object capture(Camera& camera, pybind11::object out, pybind11::object passes,
                         pybind11::object poses);

/// A shader from Python: None (unset: inherit), "builtin" (the engine's own), or a pair of
/// paths (vertex, fragment), made absolute.
std::optional<ShaderSpec> to_shader(const pybind11::handle& value, const char* what);
/// The Python value of a shader setting (None, "builtin" or a pair of paths).
pybind11::object from_shader(const std::optional<ShaderSpec>& shader);

/// CapturePass bits from pass names ("rgb", "depth", "label", "instance", "voxel",
/// "segmentation").
unsigned parse_passes(const pybind11::handle& names);
/// The names of CapturePass bits, in that order.
pybind11::list pass_names(unsigned passes);

/// add_body's physics keywords (inertia, friction, kinematic, collision_*, groups, axis, ...).
void apply_body_options(RigidBodySpec& spec, const pybind11::kwargs& kw);

/// add_joint(name, parent, child, type, **options) for World and Model.
Joint& add_joint(Model& model, const std::string& name, RigidBody& parent, RigidBody& child,
                 const std::string& type, const pybind11::kwargs& kw);

/// add_input_device(name, device, drill, **options) for World and Model.
InputDevice& add_input_device(Model& model, const std::string& name,
                              const std::shared_ptr<Device>& device, Drill& drill,
                              const pybind11::kwargs& kw);
/// The devices, InputDevice's methods and the real-time loop.
void register_devices(pybind11::module_& m,
                      pybind11::class_<InputDevice, Object, std::shared_ptr<InputDevice>>& input);
/// World.start_step_log, stop_step_log, take_step_log and the input events for plugins.
void register_world_io(pybind11::class_<World, std::shared_ptr<World>>& world);
/// A context manager holding the world's state lock for a `with` block.
pybind11::object state_lock(World& world);

/// add_drill(name, volume, **options) for World and Model.
Drill& add_drill(Model& model, const std::string& name, Volume& volume, const pybind11::kwargs& kw);

/// The Drill class's methods (the class itself is declared with the scene's).
void register_haptics(pybind11::module_& m,
                      pybind11::class_<Drill, Object, std::shared_ptr<Drill>>& drill);

/// The physics side of RigidBody and the Joint class's methods.
void register_physics(pybind11::module_& m,
                      pybind11::class_<RigidBody, Object, std::shared_ptr<RigidBody>>& body,
                      pybind11::class_<Joint, Object, std::shared_ptr<Joint>>& joint);

/// add_soft_body(name, mesh, **options), add_sensor(name, parent, **options) and
/// add_actuator(name, parent, **options) for World and Model.
SoftBody& add_soft_body(Model& model, const std::string& name, const std::string& mesh,
                        const pybind11::kwargs& kw);
ProximitySensor& add_sensor(Model& model, const std::string& name, RigidBody& parent,
                            const pybind11::kwargs& kw);
ConstraintActuator& add_actuator(Model& model, const std::string& name, RigidBody& parent,
                                 const pybind11::kwargs& kw);

/// The SoftBody, ProximitySensor and ConstraintActuator classes' methods.
void register_soft(
    pybind11::module_& m, pybind11::class_<SoftBody, Object, std::shared_ptr<SoftBody>>& soft,
    pybind11::class_<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>& sensor,
    pybind11::class_<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>& actuator);

/// A ray hit as dict(distance, position, normal, label), or None when it missed.
pybind11::object hit_dict(const VolumeHit& hit);

/// Voxels [lo, hi) of a volume, the whole grid where a bound is missing.
VoxelBox box_from(std::optional<std::array<int, 3>> lo, std::optional<std::array<int, 3>> hi,
                  const VolumeData& volume);

}  // namespace ambfplus::bindings
