// Plugins from Python: Python plugins (ambfplus.Plugin) behind a C++ adapter that takes the GIL
// for each hook only, PluginSite and PluginInfo, what World's and Simulator's plugin methods call
// (bound with the rest of those classes in py_scene.cpp), and the Python language the engine's
// loader uses for `.py` files and `ambfplus.plugins` entry points.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/plugin/plugin.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

// What a Python plugin reaches its site through (`self._site`); it forgets the plugin when the
// plugin is destroyed, so a Python object kept longer cannot reach a dead world.
struct PythonSite {
  PluginInstance* plugin = nullptr;
};

// What the Python package gives the engine when it is imported (ambfplus.plugin): the
// Plugin base class and the functions making plugins from files and entry-point names. The
// extension never imports the package back.
struct PythonSupport {
  py::object base, from_file, from_entry_point;
};
PythonSupport& support() {
  static PythonSupport* s = new PythonSupport();  // left to the interpreter's exit
  return *s;
}
const PythonSupport& checked_support() {
  if (!support().base) {
    throw PluginError("Python plugins need the ambfplus package (import ambfplus first)");
  }
  return support();
}

enum Hook {
  kPhysics,
  kGraphics,
  kKeyboard,
  kMouseButton,
  kMouseMove,
  kMouseScroll,
  kReset,
  kClose,
  kObjectAdded,
  kObjectRemoved,
  kHookCount
};
const char* const kHookNames[kHookCount] = {
    "physics_update", "graphics_update", "keyboard", "mouse_button",    "mouse_move",
    "mouse_scroll",   "reset",           "close",    "on_object_added", "on_object_removed"};

// The exception being handled as Python prints it: the traceback for unexpected errors, the
// message alone for a PluginError raised on purpose.
std::string describe_python_error(py::error_already_set& e) {
  try {
    const py::module_ traceback = py::module_::import("traceback");
    const bool expected = e.matches(py::handle(plugin_error_type()));
    py::list lines = expected ? traceback.attr("format_exception_only")(e.type(), e.value())
                              : traceback.attr("format_exception")(e.type(), e.value(), e.trace());
    std::string out;
    for (const py::handle line : lines) out += line.cast<std::string>();
    while (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  } catch (const std::exception&) {
    return e.what();
  }
}

// A Python object with plugin hooks, as a C++ plugin. Only the hooks its class defines (other
// than ambfplus.Plugin's empty ones) are called, each with the GIL held for the call alone; a
// Python exception becomes a PluginError, which the registry logs before disabling the plugin.
class PythonPlugin final : public PluginInstance {
 public:
  // With the GIL held.
  explicit PythonPlugin(py::object instance) : instance_(std::move(instance)) {
    const py::object base = checked_support().base;
    const py::object type = py::type::of(instance_);
    for (int h = 0; h < kHookCount; ++h) {
      const py::object own = py::getattr(type, kHookNames[h], py::none());
      defines_[h] = !own.is_none() && !own.is(py::getattr(base, kHookNames[h], py::none()));
    }
    site_ = py::cast(PythonSite{this});
    try {
      py::setattr(instance_, "_site", site_);
    } catch (py::error_already_set& e) {
      throw PluginError(
          "a " + py::str(type.attr("__qualname__")).cast<std::string>() +
          " cannot be a plugin: setting its _site failed: " + describe_python_error(e));
    }
  }

  ~PythonPlugin() override {
    if (!Py_IsInitialized()) {
      // The interpreter is gone: nothing to release into.
      instance_.release();
      site_.release();
      return;
    }
    py::gil_scoped_acquire gil;
    site_.cast<PythonSite&>().plugin = nullptr;
    site_ = py::object();
    instance_ = py::object();
  }

  const py::object& instance() const { return instance_; }

  int init() override {
    py::gil_scoped_acquire gil;
    try {
      if (!py::hasattr(instance_, "init")) return 1;
      const py::object result = instance_.attr("init")();
      // None (no return statement) keeps the plugin, as does True; False drops it.
      if (result.is_none()) return 1;
      if (py::isinstance<py::bool_>(result)) return result.cast<bool>() ? 1 : 0;
      if (py::isinstance<py::int_>(result)) return result.cast<int>();
      throw PluginError("init() must return an int (>= 1 keeps the plugin), not " +
                        py::str(py::type::of(result).attr("__name__")).cast<std::string>());
    } catch (py::error_already_set& e) {
      throw PluginError(describe_python_error(e));
    }
  }

  void physics_update(double dt) override {
    run(kPhysics, [&] { instance_.attr("physics_update")(dt); });
  }
  void graphics_update() override {
    run(kGraphics, [&] { instance_.attr("graphics_update")(); });
  }
  void keyboard(int key, int scancode, int action, int mods) override {
    run(kKeyboard, [&] { instance_.attr("keyboard")(key, scancode, action, mods); });
  }
  void mouse_button(int button, int action, int mods) override {
    run(kMouseButton, [&] { instance_.attr("mouse_button")(button, action, mods); });
  }
  void mouse_move(double x, double y) override {
    run(kMouseMove, [&] { instance_.attr("mouse_move")(x, y); });
  }
  void mouse_scroll(double dx, double dy) override {
    run(kMouseScroll, [&] { instance_.attr("mouse_scroll")(dx, dy); });
  }
  void reset() override {
    run(kReset, [&] { instance_.attr("reset")(); });
  }
  void close() override {
    run(kClose, [&] { instance_.attr("close")(); });
  }
  void on_object_added(Object& object) override {
    run(kObjectAdded, [&] { instance_.attr("on_object_added")(to_python(&object)); });
  }
  void on_object_removed(Object& object) override {
    run(kObjectRemoved, [&] { instance_.attr("on_object_removed")(to_python(&object)); });
  }

 private:
  template <typename Call>
  void run(Hook hook, const Call& call) {
    if (!defines_[hook]) return;
    py::gil_scoped_acquire gil;
    try {
      call();
    } catch (py::error_already_set& e) {
      throw PluginError(describe_python_error(e));
    }
  }

  py::object instance_;
  py::object site_;
  bool defines_[kHookCount] = {};
};

// The plugin behind a site, or PluginError; for handles, its simulator must be alive too.
PluginInstance& live(const PythonSite& s, bool for_handles = true) {
  if (s.plugin == nullptr) throw PluginError("this plugin is closed: its world is out of reach");
  if (for_handles && s.plugin->simulator().weak_from_this().expired()) {
    throw PluginError("plugin '" + s.plugin->name() +
                      "': its simulator is being destroyed, so handles to it cannot be made in "
                      "close(); call World.close_plugins() first to close plugins while it lives");
  }
  return *s.plugin;
}

// A plugin made by Python code (the ambfplus.plugin package's loaders), or null for None.
std::shared_ptr<PluginInstance> from_python(bool entry_point, const std::string& argument) {
  if (!Py_IsInitialized()) throw PluginError("Python plugins need a running interpreter");
  py::gil_scoped_acquire gil;
  try {
    const PythonSupport& python = checked_support();
    py::object instance = (entry_point ? python.from_entry_point : python.from_file)(argument);
    if (instance.is_none()) return nullptr;
    return std::make_shared<PythonPlugin>(std::move(instance));
  } catch (py::error_already_set& e) {
    throw PluginError(describe_python_error(e));
  }
}

// A snapshot of one attached plugin.
struct PluginInfo {
  std::string name, file, scope, language;
  bool enabled = true;
  py::object instance;     // the Python object, or None
  py::object attached_to;  // simulator, world, model or object
};

PluginInfo info(World& world, PluginInstance& p) {
  PluginInfo out;
  out.name = p.name();
  out.file = p.file();
  out.scope = plugin_scope_name(p.scope());
  out.enabled = plugins_of(world).enabled(p);
  auto* python = dynamic_cast<PythonPlugin*>(&p);
  out.language = python != nullptr ? "python" : "c++";
  out.instance = python != nullptr ? python->instance() : py::none();
  switch (p.scope()) {
    case PluginScope::kSimulator:
      out.attached_to = py::cast(p.simulator().shared_from_this());
      break;
    case PluginScope::kWorld:
      out.attached_to = py::cast(handle(&world, world));
      break;
    case PluginScope::kModel:
      out.attached_to = py::cast(handle(p.model(), world));
      break;
    case PluginScope::kObject:
      out.attached_to = to_python(p.object());
      break;
  }
  return out;
}

// World.load_plugin / Simulator.load_plugin: a file or name (str or path), or a Python plugin
// object, attached at site.
py::object load(World& world, const py::object& plugin, const PluginSite& site,
                const std::optional<std::string>& name) {
  const py::object os = py::module_::import("os");
  auto lock = lock_holding_gil(world);  // plugins load, close and reset one thread at a time
  PluginInstance* loaded = nullptr;
  if (py::isinstance<py::str>(plugin) || py::isinstance(plugin, os.attr("PathLike"))) {
    PluginSpec spec;
    spec.filename = os.attr("fspath")(plugin).cast<std::string>();
    spec.name = name.value_or("");
    py::gil_scoped_release release;
    loaded = plugins_of(world).load(spec, site);
  } else {
    auto adapter = std::make_shared<PythonPlugin>(plugin);
    const std::string type = py::str(py::type::of(plugin).attr("__name__")).cast<std::string>();
    std::string file = "<" + type + " object>";
    try {
      file = py::str(py::module_::import("inspect").attr("getfile")(py::type::of(plugin)));
    } catch (py::error_already_set&) {
      // Defined where Python keeps no file (an interactive session).
    }
    py::gil_scoped_release release;
    loaded = plugins_of(world).attach(adapter, name.value_or(type), file, site, /*native=*/false);
  }
  if (loaded == nullptr) return py::none();
  return py::cast(info(world, *loaded));
}

PluginSite site_of(World& world, const py::object& scope_object) {
  if (scope_object.is_none()) return PluginSite::of(world);
  if (py::isinstance<Simulator>(scope_object)) {
    return PluginSite::of(scope_object.cast<Simulator&>());
  }
  if (py::isinstance<World>(scope_object)) return PluginSite::of(scope_object.cast<World&>());
  if (py::isinstance<Model>(scope_object)) return PluginSite::of(scope_object.cast<Model&>());
  if (py::isinstance<Object>(scope_object)) return PluginSite::of(scope_object.cast<Object&>());
  throw py::type_error(
      "scope_object must be None (this world), a Simulator, World, Model or an "
      "object of the world");
}

}  // namespace

// Input events reach the plugins under the world's lock (a real-time loop may be stepping),
// taken holding the GIL: a Python plugin then never waits for the GIL under the lock.
void plugin_key(World& w, int key, int scancode, int action, int mods) {
  auto lock = lock_holding_gil(w);
  plugins_of(w).keyboard(key, scancode, action, mods);
}

void plugin_mouse_button(World& w, int button, int action, int mods) {
  auto lock = lock_holding_gil(w);
  plugins_of(w).mouse_button(button, action, mods);
}

void plugin_mouse_move(World& w, double x, double y) {
  auto lock = lock_holding_gil(w);
  plugins_of(w).mouse_move(x, y);
}

void plugin_mouse_scroll(World& w, double dx, double dy) {
  auto lock = lock_holding_gil(w);
  plugins_of(w).mouse_scroll(dx, dy);
}

const char* const kLoadPluginDoc =
    "Loads a plugin and calls its init(): `plugin` is a C++ library (libx.so, or a name "
    "searched in AMBFPLUS_PLUGIN_PATH, the package's plugin folder and the linker's path), a "
    "Python file (x.py), an `ambfplus.plugins` entry-point name, or an ambfplus.Plugin "
    "object. Returns its PluginInfo, or None when init() declined. Raises PluginError.";

py::object load_plugin(World& world, const py::object& plugin, const py::object& scope_object,
                       const std::optional<std::string>& name) {
  return load(world, plugin, site_of(world, scope_object), name);
}

py::object load_plugin(Simulator& simulator, const py::object& plugin,
                       const std::optional<std::string>& name) {
  return load(simulator.world(), plugin, PluginSite::of(simulator), name);
}

py::list plugin_infos(World& world) {
  py::list out;
  for (PluginInstance* p : plugins_of(world).plugins()) out.append(info(world, *p));
  return out;
}

void reset_plugins(World& world) {
  auto lock = lock_holding_gil(world);
  plugins_of(world).reset();
}

void close_plugins(World& world) {
  auto lock = lock_holding_gil(world);
  py::gil_scoped_release release;
  plugins_of(world).close_all();
}

void register_plugin(py::module_& m) {
  register_plugin_language({"python", ".py",
                            [](const std::string& file) { return from_python(false, file); },
                            [](const std::string& name) { return from_python(true, name); }});
  m.def(
      "_register_plugin_support",
      [](py::object base, py::object from_file, py::object from_entry_point) {
        support() = {std::move(base), std::move(from_file), std::move(from_entry_point)};
      },
      "Called once by ambfplus.plugin: the Plugin base class and the functions making Python "
      "plugins from a file and from an entry-point name.");

  py::class_<PythonSite>(m, "PluginSite",
                         "Where a Python plugin is attached (its `_site`); handles are made on "
                         "each access, so keep names on a plugin rather than handles.")
      .def_property_readonly(
          "name", [](const PythonSite& s) { return live(s, false).name(); }, "the declared name")
      .def_property_readonly(
          "file", [](const PythonSite& s) { return live(s, false).file(); },
          "the file it came from")
      .def_property_readonly(
          "scope", [](const PythonSite& s) { return plugin_scope_name(live(s, false).scope()); },
          "'simulator', 'world', 'model' or 'object'")
      .def_property_readonly(
          "simulator", [](const PythonSite& s) { return live(s).simulator().shared_from_this(); })
      .def_property_readonly("world",
                             [](const PythonSite& s) {
                               PluginInstance& p = live(s);
                               return handle(&p.world(), p.world());
                             })
      .def_property_readonly(
          "model",
          [](const PythonSite& s) -> py::object {
            PluginInstance& p = live(s);
            if (p.model() == nullptr) return py::none();
            return py::cast(handle(p.model(), p.world()));
          },
          "the model (model scope) or the object's model (object scope), else None")
      .def_property_readonly(
          "object", [](const PythonSite& s) { return to_python(live(s).object()); },
          "the object (object scope), else None");

  py::class_<PluginInfo>(m, "PluginInfo", "A plugin attached to a world (a snapshot).")
      .def_readonly("name", &PluginInfo::name)
      .def_readonly("file", &PluginInfo::file, "the file it was loaded from")
      .def_readonly("scope", &PluginInfo::scope, "'simulator', 'world', 'model' or 'object'")
      .def_readonly("language", &PluginInfo::language, "'c++' or 'python'")
      .def_readonly("enabled", &PluginInfo::enabled, "False once a hook of it raised")
      .def_readonly("instance", &PluginInfo::instance, "the Python plugin object, or None")
      .def_readonly("attached_to", &PluginInfo::attached_to,
                    "the simulator, world, model or object it belongs to")
      .def("__repr__", [](const PluginInfo& i) {
        return "<PluginInfo '" + i.name + "' " + i.language + " " + i.scope +
               (i.enabled ? "" : " disabled") + ">";
      });

  m.attr("PLUGIN_ABI_VERSION") = AMBFPLUS_PLUGIN_ABI_VERSION;
  m.def("plugin_search_path", &plugin_search_path,
        "The folders searched for a plugin after its declaration's own path: "
        "AMBFPLUS_PLUGIN_PATH, then the package's plugin folder.");
}

}  // namespace ambfplus::bindings
