#pragma once

// Loading plugins and calling their hooks: every world holds a PluginRegistry (World::plugins())
// with the plugins of its simulator, itself, its models and its objects.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus {

class Model;
class Object;
class Simulator;
class World;

/// What a plugin is attached to.
enum class PluginScope { kSimulator, kWorld, kModel, kObject };

/// "simulator", "world", "model" or "object".
AMBFPLUS_API const char* plugin_scope_name(PluginScope scope);

/// Where a plugin sits: its scope and the simulator, world, model and object it belongs to
/// (model is set for model and object scopes, object for object scope only).
struct AMBFPLUS_API PluginSite {
  PluginScope scope = PluginScope::kWorld;
  Simulator* simulator = nullptr;
  World* world = nullptr;
  Model* model = nullptr;
  Object* object = nullptr;

  /// The site of a plugin attached to a simulator, a world, a model or an object.
  static PluginSite of(Simulator& simulator);
  static PluginSite of(World& world);
  static PluginSite of(Model& model);
  static PluginSite of(Object& object);
};

/// A plugin as the engine holds it: a C++ library's plugin behind its C entry (plugin.h), or
/// another language's adapter (the Python bindings'). It is the engine's side of the ABI, for
/// code built with the engine; plugin libraries never see it. A hook that throws has its
/// plugin disabled by the registry.
class AMBFPLUS_API PluginInstance {
 public:
  virtual ~PluginInstance();
  /// >= 1 keeps the plugin (AMBF's rule); throwing fails the load.
  virtual int init() = 0;
  virtual void physics_update(double dt) = 0;
  virtual void graphics_update() = 0;
  virtual void keyboard(int key, int scancode, int action, int mods) = 0;
  virtual void mouse_button(int button, int action, int mods) = 0;
  virtual void mouse_move(double x, double y) = 0;
  virtual void mouse_scroll(double dx, double dy) = 0;
  virtual void reset() = 0;
  virtual void close() = 0;
  virtual void on_object_added(Object& object) = 0;
  virtual void on_object_removed(Object& object) = 0;

  const PluginSite& site() const { return site_; }
  PluginScope scope() const { return site_.scope; }
  Simulator& simulator() const { return *site_.simulator; }
  World& world() const { return *site_.world; }
  Model* model() const { return site_.model; }
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

/// A plugin to load: an ADF `plugins:` entry, a `--plugins` item or a load_plugin call.
struct AMBFPLUS_API PluginSpec {
  std::string name;      ///< what to call it; "" means the file's stem
  std::string filename;  ///< libx.so, x (tried as x, x.so, libx.so), x.py, a path, or an
                         ///< entry-point name of another language
  std::string path;      ///< a folder to look in first ("" for none)
};

/// Plugins written in another language than C++ (the Python module registers Python's). The
/// functions may throw PluginError.
struct AMBFPLUS_API PluginLanguage {
  std::string name;       ///< "python"
  std::string extension;  ///< files it loads, ".py"
  /// A plugin from a file the search found.
  std::function<std::shared_ptr<PluginInstance>(const std::string& file)> from_file;
  /// A plugin registered under a bare name (Python's entry points), or null when none is.
  std::function<std::shared_ptr<PluginInstance>(const std::string& name)> from_name;
};

/// Makes a language known to every registry (replacing one of the same name).
AMBFPLUS_API void register_plugin_language(PluginLanguage language);

/// The folders searched after a declaration's own `path`: those of AMBFPLUS_PLUGIN_PATH (colon
/// separated), then the package's plugin folder (`plugins` beside libambfplus).
AMBFPLUS_API std::vector<std::string> plugin_search_path();

/// Plugin file names replaced by others: AMBF plugins that ambfplus re-implements (AMBF's own
/// libraries cannot load here). From AMBFPLUS_PLUGIN_ALIASES ("from=to,from=to") and then the
/// package's `plugins/aliases.txt` (lines "from = to", '#' comments); the first entry wins.
AMBFPLUS_API std::map<std::string, std::string> plugin_aliases();

/// The plugins of one world, in call order: simulator, world, model, then object scope, and
/// within a scope in the order they were attached. Every hook call goes through it, so a hook
/// that throws disables its plugin (logged once) without stopping the others. It is the world's
/// last system: plugins hear of objects once every other system took them, and get their
/// physics update in the stage kPlugins (C++ plugins only under a real-time loop, whose slow
/// thread serves the others).
class AMBFPLUS_API PluginRegistry : public System {
 public:
  explicit PluginRegistry(World& world);
  ~PluginRegistry() override;
  PluginRegistry(const PluginRegistry&) = delete;
  PluginRegistry& operator=(const PluginRegistry&) = delete;

  /// Finds and loads a plugin (search order in cpp/README.md, "Plugins"), attaches it to site
  /// and calls its init(). Returns it, or nullptr when init() returned < 1 (it is dropped).
  /// Throws PluginError naming the file and every path tried, dlerror()'s message, or both ABI
  /// versions; ArgumentError for a site of another world.
  PluginInstance* load(const PluginSpec& spec, const PluginSite& site);
  /// Attaches a plugin made elsewhere as load does; native is false for plugins of another
  /// language (a Python object's adapter), whose physics updates a real-time loop decimates.
  PluginInstance* attach(std::shared_ptr<PluginInstance> plugin, const std::string& name,
                         const std::string& file, const PluginSite& site, bool native = true);

  /// Attached plugins in call order, disabled ones included.
  std::vector<PluginInstance*> plugins() const;
  /// False once a hook of the plugin threw.
  bool enabled(const PluginInstance& plugin) const;
  bool empty() const;
  /// Whether a live plugin of another language is attached (what foreign_physics_update calls).
  bool has_foreign() const;

  /// physics_update(dt) of every plugin, or with native_only of C++ plugins alone (a real-time
  /// loop's physics thread, which never waits on another language's runtime).
  void physics_update(double dt, bool native_only = false);
  /// physics_update(dt) of the plugins of other languages alone (a real-time loop calls it at a
  /// lower rate, with the time since the last call).
  void foreign_physics_update(double dt);
  void graphics_update() override;
  void keyboard(int key, int scancode, int action, int mods);
  void mouse_button(int button, int action, int mods);
  void mouse_move(double x, double y);
  void mouse_scroll(double dx, double dy);
  void reset();
  void object_added(Object& object) override;
  void object_removed(Object& object) override;

  // System
  const char* name() const override { return "plugins"; }
  unsigned stages() const override { return stage_bit(StepStage::kPlugins); }
  void run(StepStage stage, const StepContext& context) override {
    physics_update(context.dt, /*native_only=*/context.realtime);
  }
  void model_removing(Model& model) override { close_model(model); }
  void world_closing() override { close_all(); }
  /// Calls close() on every plugin in the reverse of call order, then destroys them.
  void close_all();
  /// Closes (reverse order) and destroys the plugins of a model and of its objects.
  void close_model(const Model& model);

 private:
  struct Entry;
  /// Throws ArgumentError unless site is whole and in this world.
  void check_site(const std::string& name, const PluginSite& site) const;
  template <typename Call>
  void each(const char* hook, const Call& call, const Model* model_scope_of = nullptr,
            const std::function<bool(const Entry&)>& which = nullptr);
  void close_where(const std::function<bool(const Entry&)>& which);

  World* world_;
  std::vector<std::shared_ptr<Entry>> entries_[4];  // by PluginScope
};

/// The plugins of a world (its PluginRegistry system, which engine::install_systems adds).
/// Throws StateError for a world without one.
AMBFPLUS_API PluginRegistry& plugins_of(const World& world);

}  // namespace ambfplus
