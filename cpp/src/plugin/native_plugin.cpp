#include "plugin/native_plugin.h"

#include "ambfplus/errors.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"
#include "ambfplus/version.h"

namespace ambfplus::plugin {

void check_entry(const AmbfplusPluginEntry* entry, const std::string& what) {
  if (entry == nullptr) throw PluginError(what + ": its entry point returned null");
  if (entry->abi_version != kPluginAbiVersion) {
    throw PluginError(what + ": built for plugin ABI version " +
                      std::to_string(entry->abi_version) + ", but this ambfplus (" + version() +
                      ") has plugin ABI version " + std::to_string(kPluginAbiVersion) +
                      "; rebuild the plugin against it");
  }
  const void* functions[] = {reinterpret_cast<const void*>(entry->create),
                             reinterpret_cast<const void*>(entry->destroy),
                             reinterpret_cast<const void*>(entry->init),
                             reinterpret_cast<const void*>(entry->physics_update),
                             reinterpret_cast<const void*>(entry->graphics_update),
                             reinterpret_cast<const void*>(entry->keyboard),
                             reinterpret_cast<const void*>(entry->mouse_button),
                             reinterpret_cast<const void*>(entry->mouse_move),
                             reinterpret_cast<const void*>(entry->mouse_scroll),
                             reinterpret_cast<const void*>(entry->reset),
                             reinterpret_cast<const void*>(entry->close),
                             reinterpret_cast<const void*>(entry->object_added),
                             reinterpret_cast<const void*>(entry->object_removed)};
  for (const void* f : functions) {
    if (f == nullptr) {
      throw PluginError(what +
                        ": its entry point lacks a function (export it with "
                        "AMBFPLUS_PLUGIN(YourClass) from ambfplus/plugin/plugin.h)");
    }
  }
}

NativePlugin::NativePlugin(std::shared_ptr<void> library, const AmbfplusPluginEntry& entry,
                           const PluginSite& site, const std::string& name, const std::string& file)
    : library_(std::move(library)), entry_(entry), name_(name), file_(file) {
  if (site.model != nullptr) model_ = site.model->name();
  site_.scope = static_cast<int>(site.scope);
  site_.world = reinterpret_cast<AmbfplusWorld*>(site.world);
  site_.model = site.model != nullptr ? model_.c_str() : nullptr;
  site_.object = site.object != nullptr ? site.object->id() : 0;
  site_.name = name_.c_str();
  site_.file = file_.c_str();
  const char* error = nullptr;
  instance_ = entry_.create(&site_, &error);
  if (instance_ == nullptr) {
    throw PluginError("plugin '" + name + "' (" + file + "): creating " + entry_.type_name +
                      " failed: " + (error != nullptr ? error : "create() returned null"));
  }
}

NativePlugin::~NativePlugin() {
  if (instance_ != nullptr) entry_.destroy(instance_);
}

void NativePlugin::check(AmbfplusHookResult result) {
  if (result != nullptr) throw PluginError(result);
}

int NativePlugin::init() {
  int keep = 0;
  check(entry_.init(instance_, &keep));
  return keep;
}

void NativePlugin::physics_update(double dt) { check(entry_.physics_update(instance_, dt)); }

void NativePlugin::graphics_update() { check(entry_.graphics_update(instance_)); }

void NativePlugin::keyboard(int key, int scancode, int action, int mods) {
  check(entry_.keyboard(instance_, key, scancode, action, mods));
}

void NativePlugin::mouse_button(int button, int action, int mods) {
  check(entry_.mouse_button(instance_, button, action, mods));
}

void NativePlugin::mouse_move(double x, double y) { check(entry_.mouse_move(instance_, x, y)); }

void NativePlugin::mouse_scroll(double dx, double dy) {
  check(entry_.mouse_scroll(instance_, dx, dy));
}

void NativePlugin::reset() { check(entry_.reset(instance_)); }

void NativePlugin::close() { check(entry_.close(instance_)); }

void NativePlugin::on_object_added(ambfplus::Object& object) {
  check(entry_.object_added(instance_, object.id()));
}

void NativePlugin::on_object_removed(ambfplus::Object& object) {
  check(entry_.object_removed(instance_, object.id()));
}

}  // namespace ambfplus::plugin
