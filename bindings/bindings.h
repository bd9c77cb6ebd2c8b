#pragma once

#include <type_traits>

// What the binding files share. The module is built in two passes so that every signature names
// Python classes (and the generated stubs are typed): each area first declares its classes and
// enums (declare_<area>), then defines their methods and its functions (define_<area>).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/shader_spec.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {
class Drill;
}

namespace ambfplus::bindings {

void register_errors(pybind11::module_& m);

void declare_io(pybind11::module_& m);
void declare_render(pybind11::module_& m);
void declare_capture(pybind11::module_& m);
void declare_volume(pybind11::module_& m);
void declare_scene(pybind11::module_& m);
void declare_engine(pybind11::module_& m);
void declare_haptics(pybind11::module_& m);
void declare_adf(pybind11::module_& m);
void declare_training(pybind11::module_& m);
void declare_audio(pybind11::module_& m);

void define_io(pybind11::module_& m);
void define_render(pybind11::module_& m);
void define_capture(pybind11::module_& m);
void define_volume(pybind11::module_& m);
void define_scene(pybind11::module_& m);
void define_engine(pybind11::module_& m);
void define_haptics(pybind11::module_& m);
void define_adf(pybind11::module_& m);
void define_training(pybind11::module_& m);
void define_audio(pybind11::module_& m);

void register_plugin(pybind11::module_& m);

// What World's and Simulator's plugin methods (py_scene.cpp) call (py_plugin.cpp).
extern const char* const kLoadPluginDoc;
/// World.load_plugin: scope_object None (this world), the simulator, a model or an object.
pybind11::object load_plugin(World& world, const pybind11::object& plugin,
                             const pybind11::object& scope_object,
                             const std::optional<std::string>& name);
/// Simulator.load_plugin: attached to the simulator.
pybind11::object load_plugin(Simulator& simulator, const pybind11::object& plugin,
                             const std::optional<std::string>& name);
/// World.plugins: a PluginInfo per attached plugin, in call order.
pybind11::list plugin_infos(World& world);
/// World.reset_plugins and close_plugins.
void reset_plugins(World& world);
void close_plugins(World& world);
/// The window's input events for the plugins (GLFW's codes), under the world's lock.
void plugin_key(World& w, int key, int scancode, int action, int mods);
void plugin_mouse_button(World& w, int button, int action, int mods);
void plugin_mouse_move(World& w, double x, double y);
void plugin_mouse_scroll(World& w, double dx, double dy);

/// The class a declare_* pass made, to add methods to.
template <typename... Ts>
pybind11::class_<Ts...> bound(pybind11::module_& m, const char* name) {
  return pybind11::reinterpret_borrow<pybind11::class_<Ts...>>(m.attr(name));
}

/// Every handle given to Python shares ownership of the simulator, so no handle outlives the
/// objects it points into, whatever order Python drops them in.
template <typename T>
std::shared_ptr<T> handle(T* p, World& world) {
  return std::shared_ptr<T>(world.simulator().shared_from_this(), p);
}
/// The same for an object, from its own world.
template <typename T>
std::shared_ptr<T> handle(T* p) {
  return std::shared_ptr<T>(p->world().simulator().shared_from_this(), p);
}

/// Label ids of a structure named by a label name or id, or a list of them (resolve_label's
/// rule; `what` names the caller in errors).
std::vector<std::uint16_t> structure_labels(const VolumeData& data, const pybind11::handle& labels,
                                            const std::string& what);

/// ambfplus.PluginError, the Python class (set when the module is made).
PyObject* plugin_error_type();

/// An object as its most derived Python class (None for nullptr).
pybind11::object to_python(Object* o);

/// A Python value as an option value: None, bool, int, float, str (or a path, or an enum's
/// name), an engine object, a mapping, or a sequence or array (nested lists).
OptionValue to_option(const pybind11::handle& value);
/// Keyword arguments (or a dict) as options, in the order given.
OptionMap to_options(const pybind11::handle& mapping);

/// A spec from a name and keyword options through its table (the C++ rules: unknown keys, types,
/// cross-key checks).
template <typename Spec>
Spec make_spec(const std::string& name, const OptionTable<Spec>& table, const OptionMap& options,
               Spec spec = Spec{}) {
  spec.name = name;
  table.apply(spec, options);
  return spec;
}

/// A shader from Python: None (unset: inherit), "builtin" (the engine's own), or a pair of
/// paths (vertex, fragment), made absolute.
std::optional<ShaderSpec> to_shader(const pybind11::handle& value, const char* what);
/// The Python value of a shader setting (None, "builtin" or a pair of paths).
pybind11::object from_shader(const std::optional<ShaderSpec>& shader);

/// CapturePass bits from pass names ("rgb", "depth", "label", ...).
unsigned parse_passes(const pybind11::handle& names);
/// The names of CapturePass bits, in the pass table's order.
pybind11::list pass_names(unsigned passes);
/// Camera.capture(out=None, passes=None, poses=None): renders with the GIL released.
pybind11::object capture(Camera& camera, pybind11::object out, pybind11::object passes,
                         pybind11::object poses);

/// A ray hit as dict(distance, position, normal, label, voxel), or None when it missed.
pybind11::object hit_dict(const VolumeHit& hit);
/// Voxels [lo, hi) of a volume, the whole grid where a bound is missing.
VoxelBox box_from(std::optional<std::array<int, 3>> lo, std::optional<std::array<int, 3>> hi,
                  const VolumeData& volume);

/// A read-only NumPy view (rows, 3) or of any shape: data owned by owner. Views are made
/// read-only through NumPy's own API (the `writeable` flag), not pybind11's internals.
pybind11::array readonly(pybind11::array array);

/// A context manager holding the world's state lock for a `with` block.
pybind11::object state_lock(World& world);
/// The world's state lock for a thread holding the GIL, taken so that it never waits for the
/// GIL while holding the lock (a real-time loop waiting for the lock would wait as long).
std::unique_lock<StateMutex> lock_holding_gil(World& world);
/// Runs fn() with the GIL released and takes the GIL back in the normal flow, never in a
/// destructor: a daemon thread taking it back while the interpreter finalizes is ended by Python
/// (pthread_exit, an unwind), which through pybind11's gil_scoped_release (a noexcept
/// destructor) was std::terminate ("terminate called without an active exception") at exit.
template <typename F>
decltype(auto) without_gil(F&& fn) {
  PyThreadState* state = PyEval_SaveThread();
  bool taking_back = false;
  try {
    if constexpr (std::is_void_v<decltype(fn())>) {
      fn();
      taking_back = true;
      PyEval_RestoreThread(state);
    } else {
      auto result = fn();
      taking_back = true;
      PyEval_RestoreThread(state);
      return result;
    }
  } catch (...) {
    if (!taking_back) PyEval_RestoreThread(state);
    throw;
  }
}
/// Throws StateError naming `call` while a real-time loop steps the world.
void refuse_during_loop(const World& world, const char* call);
/// A drill's distances to each critical structure, by the structure's name (its label number
/// where the label table has none), metres. Plain C++: callable under the world's lock.
std::vector<std::pair<std::string, double>> critical_distances_by_name(const Drill& drill);

}  // namespace ambfplus::bindings
