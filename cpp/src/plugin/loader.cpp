#include "plugin/loader.h"

#include <dlfcn.h>
#include <link.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <system_error>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/version.h"
#include "plugin/native_plugin.h"

namespace ambfplus {
namespace {

namespace fs = std::filesystem;

struct Languages {
  std::mutex mutex;
  std::map<std::string, PluginLanguage> by_name;
};

Languages& languages() {
  static Languages l;
  return l;
}

std::vector<PluginLanguage> registered_languages() {
  std::lock_guard<std::mutex> lock(languages().mutex);
  std::vector<PluginLanguage> out;
  for (const auto& [name, language] : languages().by_name) out.push_back(language);
  return out;
}

bool ends_with(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

std::string dl_error() {
  const char* e = dlerror();
  return e != nullptr ? e : "unknown error";
}

// The file a handle came from (the dynamic linker's own search finds it by name).
std::string loaded_path(void* handle, const std::string& fallback) {
  link_map* map = nullptr;
  if (dlinfo(handle, RTLD_DI_LINKMAP, &map) == 0 && map != nullptr && map->l_name != nullptr &&
      map->l_name[0] != '\0') {
    return map->l_name;
  }
  return fallback;
}

// Whether a symbol dlsym found is a function (a data symbol of that name would crash when
// called).
bool is_function(void* symbol) {
  Dl_info info{};
  ElfW(Sym)* entry = nullptr;
  if (dladdr1(symbol, &info, reinterpret_cast<void**>(&entry), RTLD_DL_SYMENT) == 0 ||
      entry == nullptr) {
    return false;
  }
  const int type = ELF64_ST_TYPE(entry->st_info);
  return type == STT_FUNC || type == STT_GNU_IFUNC;
}

// A plugin from an open library at site; the library stays open while the plugin lives.
std::shared_ptr<PluginInstance> from_library(void* handle, const std::string& file,
                                             const std::string& name, const PluginSite& site) {
  std::shared_ptr<void> library(handle, [](void* h) { dlclose(h); });
  const std::string what = "plugin '" + name + "' (" + file + ")";
  dlerror();
  void* symbol = dlsym(handle, AMBFPLUS_PLUGIN_ENTRY_SYMBOL);
  if (symbol == nullptr) {
    throw PluginError(what +
                      ": no entry point " AMBFPLUS_PLUGIN_ENTRY_SYMBOL
                      " (export one with AMBFPLUS_PLUGIN(YourClass) from "
                      "ambfplus/plugin/plugin.h): " +
                      dl_error());
  }
  if (!is_function(symbol)) {
    throw PluginError(what + ": " AMBFPLUS_PLUGIN_ENTRY_SYMBOL
                             " is not a function (export it with AMBFPLUS_PLUGIN(YourClass))");
  }
  const AmbfplusPluginEntry* entry = reinterpret_cast<AmbfplusPluginEntryFunction>(symbol)();
  plugin::check_entry(entry, what);
  return std::make_shared<plugin::NativePlugin>(std::move(library), *entry, site, name, file);
}

std::shared_ptr<PluginInstance> open_library(const std::string& file, const std::string& name,
                                             const PluginSite& site) {
  dlerror();
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    throw PluginError("plugin '" + name + "': cannot load " + file + ": " + dl_error());
  }
  return from_library(handle, file, name, site);
}

}  // namespace

void register_plugin_language(PluginLanguage language) {
  std::lock_guard<std::mutex> lock(languages().mutex);
  languages().by_name[language.name] = std::move(language);
}

std::map<std::string, std::string> plugin_aliases() {
  std::map<std::string, std::string> out;
  auto add = [&](const std::string& entry) {
    const std::size_t eq = entry.find('=');
    if (eq == std::string::npos) return;
    auto trim = [](std::string s) {
      const std::size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t\r");
      return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    const std::string from = trim(entry.substr(0, eq)), to = trim(entry.substr(eq + 1));
    if (!from.empty() && !to.empty()) out.emplace(from, to);  // the first wins
  };
  if (const char* env = std::getenv("AMBFPLUS_PLUGIN_ALIASES")) {
    std::istringstream items(env);
    for (std::string item; std::getline(items, item, ',');) add(item);
  }
  const std::vector<std::string> dirs = plugin_search_path();
  if (!dirs.empty()) {
    std::ifstream file(fs::path(dirs.back()) / "aliases.txt");
    for (std::string line; std::getline(file, line);) {
      if (line.empty() || line[0] == '#') continue;
      add(line);
    }
  }
  return out;
}

std::vector<std::string> plugin_search_path() {
  std::vector<std::string> out;
  if (const char* env = std::getenv("AMBFPLUS_PLUGIN_PATH")) {
    const std::string value = env;
    std::size_t start = 0;
    while (start <= value.size()) {
      const std::size_t end = std::min(value.find(':', start), value.size());
      if (end > start) out.push_back(value.substr(start, end - start));
      start = end + 1;
    }
  }
  // The folder of the library holding this function: the package (or its build-tree mirror).
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&plugin_search_path), &info) != 0 &&
      info.dli_fname != nullptr) {
    std::error_code ec;
    const fs::path library = fs::canonical(info.dli_fname, ec);
    if (!ec) out.push_back((library.parent_path() / "plugins").string());
  }
  return out;
}

namespace plugin {

std::shared_ptr<PluginInstance> make(const PluginSpec& spec, const std::string& name,
                                     const PluginSite& site, std::string& file, bool& native) {
  if (spec.filename.empty()) throw PluginError("plugin '" + name + "': no filename given");
  // An AMBF plugin ambfplus re-implements is replaced by its own (AMBF's cannot load here).
  const auto aliases = plugin_aliases();
  const auto alias = aliases.find(spec.filename);
  const std::string& f = alias != aliases.end() ? alias->second : spec.filename;
  if (alias != aliases.end()) {
    log(LogLevel::kInfo, "plugin '" + name + "': " + spec.filename + " is an AMBF plugin; " +
                             "using its ambfplus counterpart " + f + " (plugin aliases)");
  }
  const std::vector<PluginLanguage> others = registered_languages();
  const PluginLanguage* language = nullptr;
  for (const PluginLanguage& l : others) {
    if (!l.extension.empty() && ends_with(f, l.extension)) language = &l;
  }
  if (ends_with(f, ".py") && language == nullptr) {
    throw PluginError("plugin '" + name + "': " + f +
                      " is a Python plugin, which needs the ambfplus Python module");
  }
  // A library may be named without its extension, as on AMBF's other platforms.
  std::vector<std::string> names{f};
  const bool bare = fs::path(f).extension().empty() && f.find('/') == std::string::npos;
  if (language == nullptr && bare) {
    names.push_back(f + ".so");
    names.push_back("lib" + f + ".so");
  }
  std::vector<std::string> tried;
  std::error_code ec;
  auto exists = [&](const fs::path& p) {
    tried.push_back(p.string());
    return fs::is_regular_file(p, ec);
  };
  native = language == nullptr;
  auto load_file = [&](const fs::path& p) {
    file = fs::absolute(p, ec).lexically_normal().string();
    return language != nullptr ? language->from_file(file) : open_library(file, name, site);
  };

  if (f.find('/') != std::string::npos) {
    // A path: no search.
    fs::path p = f;
    if (p.is_relative() && !spec.path.empty()) p = fs::path(spec.path) / p;
    if (exists(p)) return load_file(p);
  } else {
    std::vector<std::string> dirs;
    if (!spec.path.empty()) dirs.push_back(spec.path);
    for (const std::string& d : plugin_search_path()) dirs.push_back(d);
    for (const std::string& dir : dirs) {
      for (const std::string& n : names) {
        if (exists(fs::path(dir) / n)) return load_file(fs::path(dir) / n);
      }
    }
    if (language != nullptr) {
      if (exists(fs::path(f))) return load_file(fs::path(f));  // the working directory
    } else {
      // A name another language registered (Python's entry points).
      if (bare) {
        for (const PluginLanguage& l : others) {
          if (!l.from_name) continue;
          if (std::shared_ptr<PluginInstance> p = l.from_name(f)) {
            file = l.name + " entry point '" + f + "'";
            native = false;
            return p;
          }
          tried.push_back(l.name + " entry point '" + f + "'");
        }
      }
      // The dynamic linker's own search (LD_LIBRARY_PATH, its cache, system folders).
      for (const std::string& n : names) {
        dlerror();
        if (void* handle = dlopen(n.c_str(), RTLD_NOW | RTLD_LOCAL)) {
          file = loaded_path(handle, n);
          return from_library(handle, file, name, site);
        }
        tried.push_back("dlopen(\"" + n + "\"): " + dl_error());
      }
    }
  }
  throw PluginError("plugin '" + name + "': '" + f + "' not found; tried " + join(tried));
}

}  // namespace plugin
}  // namespace ambfplus
