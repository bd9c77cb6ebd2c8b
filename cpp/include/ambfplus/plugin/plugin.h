#pragma once

// Plugins: code loaded at run time that takes part in a simulation at one of four scopes
// (simulator, world, model, object), written in C++ against this header or in Python
// (ambfplus.Plugin) with the same hooks. How they are found, loaded and called, and the order
// of their hooks, is in cpp/README.md ("Plugins").
//
// A C++ plugin derives from ambfplus::Plugin, overrides the hooks it needs and exports itself
// with AMBFPLUS_PLUGIN(ClassName) in one source file of a shared library linked against
// ambfplus::ambfplus (find_package(ambfplus CONFIG)).
//
// The ABI between the engine and a plugin library is this header's classes, laid out as the
// compiler lays them out, and the entry point below. Nothing here holds Eigen fixed-size types,
// whose alignment depends on compiler flags a plugin may not share.

#include <string>

#include "ambfplus/export.h"

/// Version of the plugin ABI (the Plugin class and AmbfplusPluginEntry). A library built
/// against another version is refused with a PluginError naming both.
#define AMBFPLUS_PLUGIN_ABI_VERSION 1

/// The entry point every plugin library exports (AMBFPLUS_PLUGIN defines it).
#define AMBFPLUS_PLUGIN_ENTRY_SYMBOL "ambfplus_plugin_entry"

namespace ambfplus {

class Model;
class Object;
class Simulator;
class World;

inline constexpr int kPluginAbiVersion = AMBFPLUS_PLUGIN_ABI_VERSION;

/// What a plugin is attached to.
enum class PluginScope { kSimulator, kWorld, kModel, kObject };

/// "simulator", "world", "model" or "object".
AMBFPLUS_API const char* plugin_scope_name(PluginScope scope);

/// Where a plugin sits: its scope and the simulator, world, model and object it belongs to
/// (model is set for model and object scopes, object for object scope only).
struct PluginSite {
  PluginScope scope = PluginScope::kWorld;
  Simulator* simulator = nullptr;
  World* world = nullptr;
  Model* model = nullptr;
  Object* object = nullptr;

  /// The site of a plugin attached to a simulator, a world, a model or an object.
  AMBFPLUS_API static PluginSite of(Simulator& simulator);
  AMBFPLUS_API static PluginSite of(World& world);
  AMBFPLUS_API static PluginSite of(Model& model);
  AMBFPLUS_API static PluginSite of(Object& object);
};

/// Base of every plugin. All hooks have empty defaults; override those you need. Hooks run on
/// the thread that steps or renders the world, one at a time. A hook that throws has its
/// plugin disabled (logged once with the exception's message); the simulation goes on.
class AMBFPLUS_API Plugin {
 public:
  Plugin() = default;
  virtual ~Plugin();
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  /// Called once when loaded, with the site already set. The plugin is kept only when it
  /// returns >= 1 (AMBF's rule); an exception fails the load with a PluginError.
  virtual int init() { return 1; }
  /// Called at the end of every world step, after physics, drills, attached objects, actuators
  /// and sensors have been updated: the world is in the state the step produced (its time and
  /// step index already advanced). Poses, forces and commands set here act from the next step.
  virtual void physics_update(double dt) {}
  /// Called before a camera renders, once per world step that renders (a stereo pair or
  /// several captures at the same step make one graphics update).
  virtual void graphics_update() {}
  /// A key event (GLFW's key codes, actions 0 release, 1 press, 2 repeat, and modifier bits).
  virtual void keyboard(int key, int scancode, int action, int mods) {}
  /// A mouse button event (GLFW's button numbers, actions and modifier bits).
  virtual void mouse_button(int button, int action, int mods) {}
  /// The cursor moved to (x, y) window pixels.
  virtual void mouse_move(double x, double y) {}
  /// The scroll wheel moved by (dx, dy).
  virtual void mouse_scroll(double dx, double dy) {}
  /// The world's plugins are reset (World::reset_plugins).
  virtual void reset() {}
  /// Called once before the plugin is destroyed: when its world is destroyed, when its model
  /// is removed, or on World::plugins().close_all(). Not called once the plugin is disabled.
  virtual void close() {}
  /// An object was added to the world (simulator and world plugins) or to this plugin's model
  /// (model plugins).
  virtual void on_object_added(Object& object) {}
  /// An object is about to be removed (it is still valid during the call); same plugins as
  /// on_object_added.
  virtual void on_object_removed(Object& object) {}

  PluginScope scope() const { return site_.scope; }
  const PluginSite& site() const { return site_; }
  Simulator& simulator() const { return *site_.simulator; }
  World& world() const { return *site_.world; }
  /// The model (model scope), or the object's model (object scope); nullptr otherwise.
  Model* model() const { return site_.model; }
  /// The object (object scope); nullptr otherwise.
  Object* object() const { return site_.object; }
  /// The name it was declared with (ADF `name`), else its file's stem.
  const std::string& name() const { return name_; }
  /// The file it was loaded from.
  const std::string& file() const { return file_; }

 private:
  friend class PluginRegistry;
  PluginSite site_;
  std::string name_;
  std::string file_;
};

}  // namespace ambfplus

extern "C" {

/// What a plugin library's entry point returns. abi_version comes first and stays first in
/// every version, so the engine can read it before trusting the rest.
struct AmbfplusPluginEntry {
  int abi_version;                          ///< AMBFPLUS_PLUGIN_ABI_VERSION it was built with
  const char* type_name;                    ///< the plugin class, for messages
  ambfplus::Plugin* (*create)();            ///< a new instance (may throw)
  void (*destroy)(ambfplus::Plugin* self);  ///< deletes an instance create made
};

/// The entry point's signature.
typedef const AmbfplusPluginEntry* (*AmbfplusPluginEntryFunction)();
}

/// Exports PluginClass (default-constructible, derived from ambfplus::Plugin) as the plugin of
/// this library. Use once per library, at namespace scope.
#define AMBFPLUS_PLUGIN(PluginClass)                                           \
  extern "C" __attribute__((visibility("default"))) const AmbfplusPluginEntry* \
  ambfplus_plugin_entry() {                                                    \
    static const AmbfplusPluginEntry entry = {                                 \
        AMBFPLUS_PLUGIN_ABI_VERSION, #PluginClass,                             \
        []() -> ::ambfplus::Plugin* { return new PluginClass(); },             \
        [](::ambfplus::Plugin* self) { delete self; }};                        \
    return &entry;                                                             \
  }
