#pragma once

// Finding a plugin's file and making the plugin: C++ libraries through dlopen, other languages
// through the factories they registered.

#include <memory>
#include <string>

#include "ambfplus/plugin/registry.h"

namespace ambfplus::plugin {

/// A new plugin for spec (called `name` in messages; a C++ library's is made at site), found in the
/// documented order: a path (a filename with '/', relative to spec.path or else the working
/// directory) is taken as given; otherwise spec.path, plugin_search_path(), then another language's
/// bare names (entry points), then the dynamic linker's own search by name. Sets file to what was
/// loaded, and native to false when another language made it. Throws PluginError listing every
/// place tried.
std::shared_ptr<PluginInstance> make(const PluginSpec& spec, const std::string& name,
                                     const PluginSite& site, std::string& file, bool& native);

}  // namespace ambfplus::plugin
