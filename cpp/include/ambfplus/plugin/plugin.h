#pragma once

// Plugins: code loaded at run time that takes part in a simulation at one of four scopes
// (simulator, world, model, object), written in C++ against this header or in Python
// (ambfplus.Plugin) with the same hooks. How they are found, loaded and called, and the order
// of their hooks, is in cpp/README.md ("Plugins").
//
// The ABI between the engine and a plugin library is C: the entry point below returns a table
// of C functions (the hooks), and the plugin reaches the world through the C functions of
// ambfplus/plugin/api.h over opaque handles and plain data (ids, numbers, double[16] poses).
// Neither side ever sees the other's class layouts, so a plugin built with other compiler flags
// than the engine (vectorisation, optimisation) works the same. What follows the entry point
// is a header-only C++ layer over both, compiled into the plugin: derive from
// ambfplus::plugin::Plugin, override the hooks you need, and put AMBFPLUS_PLUGIN(YourClass) in
// one source file of a shared library linked against ambfplus::ambfplus.

#include <array>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "ambfplus/plugin/api.h"

/// Version of the plugin ABI (AmbfplusPluginEntry and AmbfplusSite). A library built against
/// another version is refused with a PluginError naming both.
#define AMBFPLUS_PLUGIN_ABI_VERSION 2

/// The entry point every plugin library exports (AMBFPLUS_PLUGIN defines it).
#define AMBFPLUS_PLUGIN_ENTRY_SYMBOL "ambfplus_plugin_entry"

extern "C" {

/// Where a plugin sits. The engine keeps it (and its strings) alive for the plugin's life.
struct AmbfplusSite {
  int scope;             ///< 0 simulator, 1 world, 2 model, 3 object
  AmbfplusWorld* world;  ///< the world (of the simulator, for simulator plugins)
  const char* model;     ///< the model's name (model and object scopes), else NULL
  AmbfplusId object;     ///< the object (object scope), else 0
  const char* name;      ///< the name it was declared with, else its file's stem
  const char* file;      ///< the file it was loaded from
};

/// A hook's outcome: NULL when it went well, else why it failed (the text stays valid until
/// the plugin's next hook call on this thread).
typedef const char* AmbfplusHookResult;

/// What a plugin library's entry point returns: its hooks as C functions over an opaque
/// instance. abi_version comes first and stays first in every version, so the engine can read it
/// before trusting the rest. Every function pointer is set (AMBFPLUS_PLUGIN fills them all).
struct AmbfplusPluginEntry {
  int abi_version;        ///< AMBFPLUS_PLUGIN_ABI_VERSION it was built with
  const char* type_name;  ///< the plugin class, for messages
  /// A new instance at site, or NULL with *error set to why.
  void* (*create)(const AmbfplusSite* site, const char** error);
  void (*destroy)(void* self);
  /// Sets *keep to init()'s answer (>= 1 keeps the plugin).
  AmbfplusHookResult (*init)(void* self, int* keep);
  AmbfplusHookResult (*physics_update)(void* self, double dt);
  AmbfplusHookResult (*graphics_update)(void* self);
  AmbfplusHookResult (*keyboard)(void* self, int key, int scancode, int action, int mods);
  AmbfplusHookResult (*mouse_button)(void* self, int button, int action, int mods);
  AmbfplusHookResult (*mouse_move)(void* self, double x, double y);
  AmbfplusHookResult (*mouse_scroll)(void* self, double dx, double dy);
  AmbfplusHookResult (*reset)(void* self);
  AmbfplusHookResult (*close)(void* self);
  AmbfplusHookResult (*object_added)(void* self, AmbfplusId object);
  AmbfplusHookResult (*object_removed)(void* self, AmbfplusId object);
};

/// The entry point's signature.
typedef const AmbfplusPluginEntry* (*AmbfplusPluginEntryFunction)();
}

namespace ambfplus::plugin {

inline constexpr int kPluginAbiVersion = AMBFPLUS_PLUGIN_ABI_VERSION;

/// A 4x4 world-from-object pose, row-major.
using Pose = std::array<double, 16>;

/// A failed call into the engine: ambfplus_last_error()'s message.
class EngineError : public std::exception {
 public:
  explicit EngineError(std::string message) : message_(std::move(message)) {}
  const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

namespace detail {
inline int checked(int result) {
  if (result < 0) throw EngineError(ambfplus_last_error());
  return result;
}
inline AmbfplusId checked_id(AmbfplusId id) {
  if (id == 0) throw EngineError(ambfplus_last_error());
  return id;
}
inline std::string checked_text(const char* text) {
  if (text == nullptr) throw EngineError(ambfplus_last_error());
  return text;
}
}  // namespace detail

/// An object of a world, by id: everything goes through the engine's C API.
class Object {
 public:
  Object() = default;
  Object(AmbfplusWorld* world, AmbfplusId id) : world_(world), id_(id) {}
  explicit operator bool() const { return id_ != 0; }
  bool operator==(const Object& o) const { return world_ == o.world_ && id_ == o.id_; }
  AmbfplusId id() const { return id_; }
  AmbfplusWorld* world() const { return world_; }

  std::string name() const { return detail::checked_text(ambfplus_object_name(world_, id_)); }
  std::string model() const { return detail::checked_text(ambfplus_object_model(world_, id_)); }
  /// enum AmbfplusKind
  int kind() const { return detail::checked(ambfplus_object_kind(world_, id_)); }
  /// World from object, row-major.
  Pose pose() const {
    Pose p{};
    detail::checked(ambfplus_object_pose(world_, id_, p.data()));
    return p;
  }
  void set_pose(const Pose& pose) const {
    detail::checked(ambfplus_object_set_pose(world_, id_, pose.data()));
  }
  /// A property's values (api.h: ambfplus_object_get).
  std::vector<double> get(const char* property) const {
    std::vector<double> values(16);
    const int n = detail::checked(
        ambfplus_object_get(world_, id_, property, values.data(), static_cast<int>(values.size())));
    values.resize(static_cast<std::size_t>(n));
    if (n > 16) {
      detail::checked(ambfplus_object_get(world_, id_, property, values.data(), n));
    }
    return values;
  }
  double get1(const char* property) const {
    double v = 0;
    detail::checked(ambfplus_object_get(world_, id_, property, &v, 1));
    return v;
  }
  void set(const char* property, const std::vector<double>& values) const {
    detail::checked(
        ambfplus_object_set(world_, id_, property, values.data(), static_cast<int>(values.size())));
  }
  void set1(const char* property, double value) const {
    detail::checked(ambfplus_object_set(world_, id_, property, &value, 1));
  }
  /// Moves with parent (api.h: ambfplus_object_attach); local null: where it is now.
  void attach_to(const Object& parent, const Pose* local = nullptr) const {
    detail::checked(ambfplus_object_attach(world_, id_, parent.id_,
                                           local != nullptr ? local->data() : nullptr));
  }

 private:
  AmbfplusWorld* world_ = nullptr;
  AmbfplusId id_ = 0;
};

/// A world, through the engine's C API.
class World {
 public:
  World() = default;
  explicit World(AmbfplusWorld* world) : world_(world) {}
  AmbfplusWorld* handle() const { return world_; }

  std::string name() const { return detail::checked_text(ambfplus_world_name(world_)); }
  double time() const { return ambfplus_world_time(world_); }
  std::int64_t step_index() const { return ambfplus_world_step_index(world_); }
  double time_step() const { return ambfplus_world_time_step(world_); }
  /// The simulator's plugin arguments (the command line's unknown options).
  std::vector<std::string> arguments() const {
    std::vector<std::string> out;
    const int n = ambfplus_world_argument_count(world_);
    for (int i = 0; i < n; ++i) out.push_back(ambfplus_world_argument(world_, i));
    return out;
  }
  /// Objects in creation order, of one kind (AmbfplusKind) or all.
  std::vector<Object> objects(int kind = AMBFPLUS_ANY) const {
    std::vector<Object> out;
    const int n = ambfplus_world_object_count(world_);
    for (int i = 0; i < n; ++i) {
      const Object o(world_, ambfplus_world_object(world_, i));
      if (kind == AMBFPLUS_ANY || o.kind() == kind) out.push_back(o);
    }
    return out;
  }
  /// The object with exactly this name (false when there is none).
  Object find(const std::string& name, int kind = AMBFPLUS_ANY) const {
    return Object(world_, ambfplus_world_find(world_, name.c_str(), kind));
  }
  /// Objects a name refers to, as AMBF finds them.
  std::vector<Object> lookup(const std::string& query, int kind = AMBFPLUS_ANY) const {
    const int n = detail::checked(ambfplus_world_lookup(world_, query.c_str(), kind, nullptr, 0));
    std::vector<AmbfplusId> ids(static_cast<std::size_t>(n));
    detail::checked(ambfplus_world_lookup(world_, query.c_str(), kind, ids.data(), n));
    std::vector<Object> out;
    for (AmbfplusId id : ids) out.emplace_back(world_, id);
    return out;
  }
  /// Creates a body or a drill (api.h: ambfplus_world_add).
  Object add(const char* kind, const std::string& name, const std::vector<AmbfplusOption>& options,
             const char* model = nullptr) const {
    return Object(world_, detail::checked_id(ambfplus_world_add(world_, model, kind, name.c_str(),
                                                                options.data(),
                                                                static_cast<int>(options.size()))));
  }

 private:
  AmbfplusWorld* world_ = nullptr;
};

/// What a scope a plugin is attached at (AmbfplusSite::scope).
enum class Scope { kSimulator = 0, kWorld = 1, kModel = 2, kObject = 3 };

/// Base of every C++ plugin. All hooks have empty defaults; override those you need. Hooks run
/// on the thread that steps or renders the world, one at a time, with the world's state lock
/// held. A hook that throws has its plugin disabled (logged once with the exception's message);
/// the simulation goes on.
class Plugin {
 public:
  Plugin() = default;
  virtual ~Plugin() = default;
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  /// Called once when loaded, with the site set. The plugin is kept only when it returns >= 1
  /// (AMBF's rule); an exception fails the load with a PluginError.
  virtual int init() { return 1; }
  /// Called at the end of every world step, in the stage kPlugins: the world is in the state
  /// the step produced (its time and step index already advanced). What it sets acts from the
  /// next step.
  virtual void physics_update(double dt) {}
  /// Called before a camera renders, once per world step that renders.
  virtual void graphics_update() {}
  /// A key event (GLFW's key codes, actions 0 release, 1 press, 2 repeat, and modifier bits).
  virtual void keyboard(int key, int scancode, int action, int mods) {}
  /// A mouse button event (GLFW's button numbers, actions and modifier bits).
  virtual void mouse_button(int button, int action, int mods) {}
  /// The cursor moved to (x, y) window pixels.
  virtual void mouse_move(double x, double y) {}
  /// The scroll wheel moved by (dx, dy).
  virtual void mouse_scroll(double dx, double dy) {}
  /// The world's plugins are reset.
  virtual void reset() {}
  /// Called once before the plugin is destroyed (not once it is disabled).
  virtual void close() {}
  /// An object was added to the world (simulator and world plugins) or to this plugin's model
  /// (model plugins).
  virtual void on_object_added(const Object& object) {}
  /// An object is about to be removed (it is still there during the call).
  virtual void on_object_removed(const Object& object) {}

  Scope scope() const { return static_cast<Scope>(site_.scope); }
  World world() const { return World(site_.world); }
  /// The model's name (model and object scopes), else "".
  std::string model() const { return site_.model != nullptr ? site_.model : ""; }
  /// The object (object scope), else a false Object.
  Object object() const { return Object(site_.world, site_.object); }
  /// The name it was declared with (ADF `name`), else its file's stem.
  std::string name() const { return site_.name != nullptr ? site_.name : ""; }
  /// The file it was loaded from.
  std::string file() const { return site_.file != nullptr ? site_.file : ""; }

  /// Set by AMBFPLUS_PLUGIN's create() before init.
  void set_site(const AmbfplusSite& site) { site_ = site; }

 private:
  AmbfplusSite site_{};
};

namespace detail {

/// Runs a hook of the plugin's own code, turning an exception into the message the engine logs.
template <typename Call>
AmbfplusHookResult guarded(const Call& call) {
  static thread_local std::string message;
  try {
    call();
    return nullptr;
  } catch (const std::exception& e) {
    message = e.what();
  } catch (...) {
    message = "an exception of unknown type";
  }
  return message.c_str();
}

/// The C functions of a plugin class's entry.
template <typename PluginClass>
struct Entry {
  static PluginClass& self(void* p) { return *static_cast<PluginClass*>(p); }
  static void* create(const AmbfplusSite* site, const char** error) {
    static thread_local std::string message;
    try {
      auto* plugin = new PluginClass();
      plugin->set_site(*site);
      return plugin;
    } catch (const std::exception& e) {
      message = e.what();
    } catch (...) {
      message = "an exception of unknown type";
    }
    *error = message.c_str();
    return nullptr;
  }
  static void destroy(void* p) { delete static_cast<PluginClass*>(p); }
  static AmbfplusHookResult init(void* p, int* keep) {
    return guarded([&] { *keep = self(p).init(); });
  }
  static AmbfplusHookResult physics_update(void* p, double dt) {
    return guarded([&] { self(p).physics_update(dt); });
  }
  static AmbfplusHookResult graphics_update(void* p) {
    return guarded([&] { self(p).graphics_update(); });
  }
  static AmbfplusHookResult keyboard(void* p, int key, int scancode, int action, int mods) {
    return guarded([&] { self(p).keyboard(key, scancode, action, mods); });
  }
  static AmbfplusHookResult mouse_button(void* p, int button, int action, int mods) {
    return guarded([&] { self(p).mouse_button(button, action, mods); });
  }
  static AmbfplusHookResult mouse_move(void* p, double x, double y) {
    return guarded([&] { self(p).mouse_move(x, y); });
  }
  static AmbfplusHookResult mouse_scroll(void* p, double dx, double dy) {
    return guarded([&] { self(p).mouse_scroll(dx, dy); });
  }
  static AmbfplusHookResult reset(void* p) {
    return guarded([&] { self(p).reset(); });
  }
  static AmbfplusHookResult close(void* p) {
    return guarded([&] { self(p).close(); });
  }
  static AmbfplusHookResult object_added(void* p, AmbfplusId id) {
    return guarded([&] { self(p).on_object_added(Object(self(p).world().handle(), id)); });
  }
  static AmbfplusHookResult object_removed(void* p, AmbfplusId id) {
    return guarded([&] { self(p).on_object_removed(Object(self(p).world().handle(), id)); });
  }
};

}  // namespace detail
}  // namespace ambfplus::plugin

/// Exports PluginClass (default-constructible, derived from ambfplus::plugin::Plugin) as the
/// plugin of this library. Use once per library, at namespace scope.
#define AMBFPLUS_PLUGIN(PluginClass)                                             \
  extern "C" __attribute__((visibility("default"))) const AmbfplusPluginEntry*   \
  ambfplus_plugin_entry() {                                                      \
    using AmbfplusEntryOf = ::ambfplus::plugin::detail::Entry<PluginClass>;      \
    static const AmbfplusPluginEntry entry = {AMBFPLUS_PLUGIN_ABI_VERSION,       \
                                              #PluginClass,                      \
                                              &AmbfplusEntryOf::create,          \
                                              &AmbfplusEntryOf::destroy,         \
                                              &AmbfplusEntryOf::init,            \
                                              &AmbfplusEntryOf::physics_update,  \
                                              &AmbfplusEntryOf::graphics_update, \
                                              &AmbfplusEntryOf::keyboard,        \
                                              &AmbfplusEntryOf::mouse_button,    \
                                              &AmbfplusEntryOf::mouse_move,      \
                                              &AmbfplusEntryOf::mouse_scroll,    \
                                              &AmbfplusEntryOf::reset,           \
                                              &AmbfplusEntryOf::close,           \
                                              &AmbfplusEntryOf::object_added,    \
                                              &AmbfplusEntryOf::object_removed}; \
    return &entry;                                                               \
  }
