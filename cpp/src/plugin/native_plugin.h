#pragma once

// A C++ plugin library's plugin, as the engine holds it: its C entry's hooks over an instance
// the library made, and the site (with its strings) the library was given.

#include <memory>
#include <string>

#include "ambfplus/plugin/plugin.h"
#include "ambfplus/plugin/registry.h"

namespace ambfplus::plugin {

class NativePlugin final : public PluginInstance {
 public:
  /// Makes an instance with the library's create() at site. Throws PluginError when create
  /// fails. The library stays open while the instance lives.
  NativePlugin(std::shared_ptr<void> library, const AmbfplusPluginEntry& entry,
               const PluginSite& site, const std::string& name, const std::string& file);
  ~NativePlugin() override;

  int init() override;
  void physics_update(double dt) override;
  void graphics_update() override;
  void keyboard(int key, int scancode, int action, int mods) override;
  void mouse_button(int button, int action, int mods) override;
  void mouse_move(double x, double y) override;
  void mouse_scroll(double dx, double dy) override;
  void reset() override;
  void close() override;
  void on_object_added(ambfplus::Object& object) override;
  void on_object_removed(ambfplus::Object& object) override;

 private:
  /// Throws PluginError with the hook's message when it failed.
  static void check(AmbfplusHookResult result);

  std::shared_ptr<void> library_;
  const AmbfplusPluginEntry& entry_;
  std::string model_, name_, file_;  // what site_.model, .name and .file point into
  AmbfplusSite site_{};
  void* instance_ = nullptr;
};

/// Checks a library's entry: the ABI version first, then that every function is there. Throws
/// PluginError naming `what` and what is wrong.
void check_entry(const AmbfplusPluginEntry* entry, const std::string& what);

}  // namespace ambfplus::plugin
