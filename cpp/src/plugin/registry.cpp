#include "ambfplus/plugin/registry.h"

#include <filesystem>
#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"
#include "plugin/loader.h"

namespace ambfplus {

struct PluginRegistry::Entry {
  std::shared_ptr<PluginInstance> plugin;
  bool enabled = true;   // false once a hook threw
  bool attached = true;  // false once closed
  bool native = true;    // C++ (not another language's adapter)
};

namespace {

std::string describe(const PluginInstance& p) {
  std::string where = plugin_scope_name(p.scope());
  if (p.object() != nullptr) {
    where += " '" + p.object()->name() + "'";
  } else if (p.scope() == PluginScope::kModel && p.model() != nullptr) {
    where += " '" + p.model()->name() + "'";
  }
  return "plugin '" + p.name() + "' (" + p.file() + ", " + where + ")";
}

}  // namespace

const char* plugin_scope_name(PluginScope scope) {
  switch (scope) {
    case PluginScope::kSimulator:
      return "simulator";
    case PluginScope::kWorld:
      return "world";
    case PluginScope::kModel:
      return "model";
    case PluginScope::kObject:
      return "object";
  }
  return "?";
}

PluginSite PluginSite::of(Simulator& simulator) {
  return {PluginScope::kSimulator, &simulator, &simulator.world(), nullptr, nullptr};
}

PluginSite PluginSite::of(World& world) {
  return {PluginScope::kWorld, &world.simulator(), &world, nullptr, nullptr};
}

PluginSite PluginSite::of(Model& model) {
  return {PluginScope::kModel, &model.world().simulator(), &model.world(), &model, nullptr};
}

PluginSite PluginSite::of(Object& object) {
  return {PluginScope::kObject, &object.world().simulator(), &object.world(), &object.model(),
          &object};
}

PluginInstance::~PluginInstance() = default;

PluginRegistry::PluginRegistry(World& world) : world_(&world) {}

PluginRegistry& plugins_of(const World& world) {
  if (auto* plugins = world.find_system<PluginRegistry>()) return *plugins;
  throw StateError("world '" + world.name() + "' has no plugins (make it with the engine)");
}

PluginRegistry::~PluginRegistry() = default;

void PluginRegistry::check_site(const std::string& name, const PluginSite& site) const {
  const bool complete = site.simulator != nullptr && site.world == world_ &&
                        (site.scope < PluginScope::kModel || site.model != nullptr) &&
                        (site.scope != PluginScope::kObject || site.object != nullptr);
  if (!complete) {
    throw ArgumentError("plugin '" + name + "': its site is not in this world or lacks its " +
                        std::string(plugin_scope_name(site.scope)));
  }
}

PluginInstance* PluginRegistry::load(const PluginSpec& spec, const PluginSite& site) {
  if (site.world != world_) {
    throw ArgumentError("a plugin can only be attached to this world or what it holds");
  }
  const std::string name =
      spec.name.empty() ? std::filesystem::path(spec.filename).stem().string() : spec.name;
  std::string file;
  bool native = true;
  check_site(name, site);
  std::shared_ptr<PluginInstance> plugin = plugin::make(spec, name, site, file, native);
  return attach(std::move(plugin), name, file, site, native);
}

PluginInstance* PluginRegistry::attach(std::shared_ptr<PluginInstance> plugin,
                                       const std::string& name, const std::string& file,
                                       const PluginSite& site, bool native) {
  if (!plugin) throw ArgumentError("no plugin to attach");
  check_site(name, site);
  plugin->site_ = site;
  plugin->name_ = name;
  plugin->file_ = file;
  int keep = 0;
  try {
    keep = plugin->init();
  } catch (const std::exception& e) {
    throw PluginError(describe(*plugin) + ": init() failed: " + e.what());
  } catch (...) {
    throw PluginError(describe(*plugin) + ": init() failed with an unknown exception");
  }
  if (keep < 1) {
    log(LogLevel::kInfo,
        describe(*plugin) + ": init() returned " + std::to_string(keep) + ", so it is not kept");
    return nullptr;
  }
  auto entry = std::make_shared<Entry>();
  entry->plugin = std::move(plugin);
  entry->native = native;
  entries_[static_cast<int>(site.scope)].push_back(entry);
  return entry->plugin.get();
}

std::vector<PluginInstance*> PluginRegistry::plugins() const {
  std::vector<PluginInstance*> out;
  for (const auto& scope : entries_) {
    for (const auto& e : scope) out.push_back(e->plugin.get());
  }
  return out;
}

bool PluginRegistry::enabled(const PluginInstance& plugin) const {
  for (const auto& scope : entries_) {
    for (const auto& e : scope) {
      if (e->plugin.get() == &plugin) return e->enabled;
    }
  }
  return false;
}

bool PluginRegistry::empty() const {
  for (const auto& scope : entries_) {
    if (!scope.empty()) return false;
  }
  return true;
}

bool PluginRegistry::has_foreign() const {
  for (const auto& scope : entries_) {
    for (const auto& e : scope) {
      if (!e->native && e->attached && e->enabled) return true;
    }
  }
  return false;
}

// Calls a hook on every live plugin in call order (model plugins only of model_scope_of when it
// is given, object plugins then left out). Plugins attached or removed by a hook take part from
// the next call on.
template <typename Call>
void PluginRegistry::each(const char* hook, const Call& call, const Model* model_scope_of,
                          const std::function<bool(const Entry&)>& which) {
  if (empty()) return;
  std::vector<std::shared_ptr<Entry>> snapshot;
  for (const auto& scope : entries_) snapshot.insert(snapshot.end(), scope.begin(), scope.end());
  for (const auto& e : snapshot) {
    if (!e->enabled || !e->attached || (which && !which(*e))) continue;
    PluginInstance& p = *e->plugin;
    if (model_scope_of != nullptr &&
        (p.scope() == PluginScope::kObject ||
         (p.scope() == PluginScope::kModel && p.model() != model_scope_of))) {
      continue;
    }
    try {
      call(p);
    } catch (const std::exception& ex) {
      e->enabled = false;
      log(LogLevel::kError,
          describe(p) + ": " + hook + " failed, so the plugin is disabled: " + ex.what());
    } catch (...) {
      e->enabled = false;
      log(LogLevel::kError, describe(p) + ": " + hook +
                                " failed with an unknown exception, so the plugin is "
                                "disabled");
    }
  }
}

void PluginRegistry::physics_update(double dt, bool native_only) {
  if (!native_only) {
    each("physics_update", [dt](PluginInstance& p) { p.physics_update(dt); });
    return;
  }
  each(
      "physics_update", [dt](PluginInstance& p) { p.physics_update(dt); }, nullptr,
      [](const Entry& e) { return e.native; });
}

void PluginRegistry::foreign_physics_update(double dt) {
  each(
      "physics_update", [dt](PluginInstance& p) { p.physics_update(dt); }, nullptr,
      [](const Entry& e) { return !e.native; });
}

void PluginRegistry::graphics_update() {
  each("graphics_update", [](PluginInstance& p) { p.graphics_update(); });
}

void PluginRegistry::keyboard(int key, int scancode, int action, int mods) {
  each("keyboard", [&](PluginInstance& p) { p.keyboard(key, scancode, action, mods); });
}

void PluginRegistry::mouse_button(int button, int action, int mods) {
  each("mouse_button", [&](PluginInstance& p) { p.mouse_button(button, action, mods); });
}

void PluginRegistry::mouse_move(double x, double y) {
  each("mouse_move", [&](PluginInstance& p) { p.mouse_move(x, y); });
}

void PluginRegistry::mouse_scroll(double dx, double dy) {
  each("mouse_scroll", [&](PluginInstance& p) { p.mouse_scroll(dx, dy); });
}

void PluginRegistry::reset() {
  each("reset", [](PluginInstance& p) { p.reset(); });
}

void PluginRegistry::object_added(Object& object) {
  each("on_object_added", [&](PluginInstance& p) { p.on_object_added(object); }, &object.model());
}

void PluginRegistry::object_removed(Object& object) {
  each(
      "on_object_removed", [&](PluginInstance& p) { p.on_object_removed(object); },
      &object.model());
}

void PluginRegistry::close_where(const std::function<bool(const Entry&)>& which) {
  std::vector<std::shared_ptr<Entry>> closing;
  for (int s = 3; s >= 0; --s) {
    auto& scope = entries_[s];
    for (auto it = scope.rbegin(); it != scope.rend(); ++it) {
      if ((*it)->attached && which(**it)) closing.push_back(*it);
    }
  }
  // Out of the registry first: a close() that loads or removes plugins sees a consistent list.
  for (auto& scope : entries_) {
    std::vector<std::shared_ptr<Entry>> kept;
    for (auto& e : scope) {
      if (!(e->attached && which(*e))) kept.push_back(std::move(e));
    }
    scope = std::move(kept);
  }
  for (const auto& e : closing) {
    e->attached = false;
    if (!e->enabled) continue;
    try {
      e->plugin->close();
    } catch (const std::exception& ex) {
      log(LogLevel::kError, describe(*e->plugin) + ": close failed: " + ex.what());
    } catch (...) {
      log(LogLevel::kError, describe(*e->plugin) + ": close failed with an unknown exception");
    }
  }
  // Destroyed in the order they were closed.
  for (auto& e : closing) e.reset();
}

void PluginRegistry::close_all() {
  close_where([](const Entry&) { return true; });
}

void PluginRegistry::close_model(const Model& model) {
  close_where([&](const Entry& e) { return e.plugin->model() == &model; });
}

}  // namespace ambfplus
