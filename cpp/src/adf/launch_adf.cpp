// Launch, world, colour and input-device files, and loading a launch into a world.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <system_error>

#include <Eigen/Geometry>

#include "adf/adf_internal.h"
#include "ambfplus/log.h"
#include "ambfplus/physics/physics.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

using adf::Doc;
namespace fs = std::filesystem;

std::vector<AdfPlugin> adf::read_plugins(const Doc& doc, const YAML::Node& list,
                                         const std::string& where) {
  std::vector<AdfPlugin> out;
  if (!list) return out;
  if (!list.IsSequence()) adf::fail(doc, list, where, "'plugins' must be a list");
  for (const YAML::Node& p : list) {
    AdfPlugin plugin;
    if (!p["filename"]) adf::fail(doc, p, where, "a plugin needs 'filename'");
    plugin.filename = adf::text(doc, p["filename"], where, "plugins.filename");
    plugin.name = p["name"] ? adf::text(doc, p["name"], where, "plugins.name") : plugin.filename;
    if (p["path"])
      plugin.path = adf::resolve(doc.dir, adf::text(doc, p["path"], where, "plugins.path"));
    out.push_back(std::move(plugin));
  }
  return out;
}

std::optional<ShaderSpec> adf::read_shader(const Doc& doc, const YAML::Node& block,
                                           const std::string& where, const std::string& key,
                                           Context& ctx) {
  if (!block) return std::nullopt;
  if (!block.IsMap())
    adf::fail(doc, block, where, "'" + key + "' must be {path, vertex, fragment}");
  for (const char* part : {"vertex", "fragment"}) {
    if (!block[part]) adf::fail(doc, block, where, "'" + key + "' needs '" + part + "'");
  }
  const std::string dir =
      block["path"] ? adf::resolve(doc.dir, adf::text(doc, block["path"], where, key + ".path"))
                    : doc.dir.string();
  ShaderSpec spec;
  spec.vertex = adf::resolve(dir, adf::text(doc, block["vertex"], where, key + ".vertex"));
  spec.fragment = adf::resolve(dir, adf::text(doc, block["fragment"], where, key + ".fragment"));
  for (const std::string* file : {&spec.vertex, &spec.fragment}) {
    if (!fs::is_regular_file(*file)) {
      ctx.diag->warn(doc.path, adf::at(block) + where + ": '" + key + "': " + *file +
                                   " not found; the engine's own shader draws instead");
      return std::nullopt;
    }
  }
  return spec;
}

void adf::load_plugins(const std::vector<AdfPlugin>& plugins, const PluginSite& site,
                       const std::string& file, const std::string& where, Context& ctx) {
  for (const AdfPlugin& p : plugins) {
    try {
      if (plugins_of(*site.world).load(PluginSpec{p.name, p.filename, p.path}, site) == nullptr) {
        ctx.diag->warn(file, where + ": plugin '" + (p.name.empty() ? p.filename : p.name) +
                                 "' is not kept: its init() returned less than 1");
      }
    } catch (const PluginError& e) {
      if (!ctx.report_plugin_errors) throw PluginError(file + ": " + where + ": " + e.what());
      ctx.diag->error(file, where + ": " + e.what());
    }
  }
}

void adf::load_plugins(const std::vector<ObjectPlugins>& objects, const std::string& file,
                       Context& ctx) {
  for (const ObjectPlugins& o : objects) {
    load_plugins(o.plugins, PluginSite::of(*o.object), file, o.where, ctx);
  }
}

namespace {

// The plugins of objects made while resolve_deferred runs, with their files.
thread_local std::vector<std::pair<adf::ObjectPlugins, std::string>>* made_late = nullptr;

}  // namespace

void adf::load_plugins_later(ObjectPlugins plugins, std::string file) {
  if (made_late == nullptr) {
    // Deferred links are only resolved by resolve_deferred; kept honest all the same.
    log(LogLevel::kWarning, file + ": " + plugins.where + ": its plugins are not loaded");
    return;
  }
  made_late->emplace_back(std::move(plugins), std::move(file));
}

void adf::resolve_deferred(World& world, Context& ctx) {
  std::vector<std::pair<ObjectPlugins, std::string>> made;
  made_late = &made;
  try {
    world.resolve_deferred_links();
    made_late = nullptr;
  } catch (const Error& e) {
    made_late = nullptr;
    if (!ctx.report_plugin_errors) throw;
    ctx.diag->error("", std::string("attaching to a parent loaded later: ") + e.what());
  }
  // Their files are built, and so is the one that brought what they waited for.
  for (const auto& [o, file] : made) {
    load_plugins(o.plugins, PluginSite::of(*o.object), file, o.where, ctx);
  }
}

void adf::warn_unresolved(const World& world, Context& ctx) {
  for (const DeferredLink& link : world.deferred_links()) {
    ctx.diag->warn(link.file, link.description);
  }
}

namespace {

// Static planes around the origin: AMBF's `enclosure` when a world has no environment.
void add_enclosure(World& world, const Doc& doc, const YAML::Node& node) {
  if (!node.IsMap() && !node.IsNull()) {
    adf::fail(doc, node, "enclosure", "'enclosure' must be {length, width, height}");
  }
  auto size = [&](const char* key, double fallback) {
    const double value = adf::number_or(doc, node, key, "enclosure", fallback);
    if (!(value > 0)) {
      adf::fail(doc, node[key], "enclosure",
                std::string("'enclosure.") + key + "' must be > 0 m, got " + node[key].Scalar());
    }
    return value;
  };
  const double length = size("length", 4.0);
  const double width = size("width", 4.0);
  const double height = size("height", 3.0);
  Model& model = world.add_model(adf::unique_model_name(world, "enclosure"));
  struct Wall {
    const char* name;
    Eigen::Vector3d normal;
    double distance;
  };
  const Wall walls[] = {{"enclosure_floor", Eigen::Vector3d::UnitZ(), height / 2},
                        {"enclosure_wall_x_neg", Eigen::Vector3d::UnitX(), length / 2},
                        {"enclosure_wall_x_pos", -Eigen::Vector3d::UnitX(), length / 2},
                        {"enclosure_wall_y_neg", Eigen::Vector3d::UnitY(), width / 2},
                        {"enclosure_wall_y_pos", -Eigen::Vector3d::UnitY(), width / 2}};
  for (const Wall& w : walls) {
    RigidBodySpec spec;
    spec.name = adf::unique_name(world, world.name_space(), w.name, "the world's enclosure", model);
    spec.shape.kind = Shape::Kind::kPlane;
    spec.dynamics.mass = 0;
    spec.pose.topLeftCorner<3, 3>() =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), w.normal).toRotationMatrix();
    spec.pose.topRightCorner<3, 1>() = -w.normal * w.distance;
    const adf::InNameSpace in_ns(model, world.name_space());
    model.add_body(spec);
  }
}

void load_world(World& world, const std::string& path, adf::Context& ctx) {
  const Doc doc = adf::load(path, "world file", ctx.diag);
  const YAML::Node& root = doc.root;
  const std::string where = "world";
  static const std::set<std::string> known = {
      "namespace",      "enclosure", "lights",  "cameras", "environment", "skybox",
      "max iterations", "gravity",   "shaders", "plugins", "adf version"};
  ctx.diag->unknown_top_level(doc, known, {"lights", "cameras"});
  // Read everything first: a bad key fails before the world changes.
  const std::string ns =
      adf::join_ns(ctx.prefix, "/ambf/env/",
                   root["namespace"] ? adf::text(doc, root["namespace"], where, "namespace") : "");
  Eigen::Vector3d gravity = physics::physics_of(world).gravity();
  gravity = adf::xyz(doc, root["gravity"], where, "gravity", gravity);
  // AMBF's cap on fixed sub-steps per real-time update (Bullet's maxSubSteps); a fixed-step
  // world takes exactly the steps asked for, so it is only checked.
  if (root["max iterations"] &&
      adf::integer(doc, root["max iterations"], where, "max iterations") < 1) {
    adf::fail(doc, root["max iterations"], where, "'max iterations' must be >= 1");
  }
  std::string environment;
  if (root["environment"]) {
    environment = adf::resolve(doc.dir, adf::text(doc, root["environment"], where, "environment"));
  }
  if (root["skybox"]) {
    ctx.diag->warn(doc.path, adf::at(root["skybox"]) + "world 'skybox' is not applied yet");
  }
  const std::optional<ShaderSpec> shader =
      adf::read_shader(doc, root["shaders"], where, "shaders", ctx);
  const std::vector<AdfPlugin> plugins = adf::read_plugins(doc, root["plugins"], where);

  world.set_name_space(ns);
  physics::physics_of(world).set_gravity(gravity);
  // Lights and cameras may ride on bodies of the environment, so it comes first.
  std::vector<std::pair<std::string, RigidBody*>> own;
  if (!environment.empty()) {
    Model* env = nullptr;
    try {
      ctx.skip_missing_meshes = ctx.report_environment_errors;
      env = &adf::yaml_checked(
          environment, [&]() -> Model& { return adf::load_model(world, environment, ctx); });
      ctx.skip_missing_meshes = false;
    } catch (const Error& e) {
      ctx.skip_missing_meshes = false;
      // AMBF reports an environment it cannot build and goes on with the world.
      if (!ctx.report_environment_errors) throw;
      ctx.diag->error(environment, std::string("world environment not loaded: ") + e.what());
    }
    if (env != nullptr) {
      // AMBF builds the environment before it compiles the world's shader, which the
      // environment therefore never gets.
      if (shader && !env->shader()) env->set_shader(ShaderSpec{});
      for (Object* o : env->objects()) {
        if (auto* b = dynamic_cast<RigidBody*>(o)) own.emplace_back(b->identifier(), b);
      }
    }
  } else if (root["enclosure"]) {
    add_enclosure(world, doc, root["enclosure"]);
  }
  if (shader) world.set_shader(shader);
  std::vector<adf::ObjectPlugins> object_plugins;
  ctx.diag->repeated_entries(doc, {"cameras", "lights"});
  ctx.diag->repeated_names(doc, {"cameras", "lights"});
  adf::add_cameras_and_lights(world.default_model(), doc, ns, ctx, own, object_plugins);
  // Plugins once the world is built: its objects', then its own.
  adf::load_plugins(object_plugins, doc.path, ctx);
  adf::load_plugins(plugins, PluginSite::of(world), doc.path, where, ctx);
}

}  // namespace

AdfLaunch read_launch(const std::string& path) {
  adf::Diagnostics diag;  // its warnings are logged
  const Doc doc = adf::load(path, "launch file", &diag);
  AdfLaunch launch;
  launch.file = fs::absolute(path).lexically_normal().string();
  auto need = [&](const char* key) {
    const YAML::Node n = doc.root[key];
    if (!n) {
      throw ConfigError(doc.path, std::string("launch file: needs '") + key + "'");
    }
    return n;
  };
  launch.world =
      adf::resolve(doc.dir, adf::text(doc, need("world config"), "launch", "world config"));
  launch.colors =
      adf::resolve(doc.dir, adf::text(doc, need("color config"), "launch", "color config"));
  launch.input_devices = adf::resolve(
      doc.dir, adf::text(doc, need("input devices config"), "launch", "input devices config"));
  const YAML::Node models = need("multibody configs");
  if (!models.IsSequence()) adf::fail(doc, models, "launch", "'multibody configs' must be a list");
  for (const YAML::Node& m : models) {
    launch.models.push_back(
        adf::resolve(doc.dir, adf::text(doc, m, "launch", "multibody configs")));
  }
  launch.plugins = adf::read_plugins(doc, doc.root["plugins"], "launch");
  return launch;
}

AdfColors read_colors(const std::string& path) {
  adf::Diagnostics diag;  // its warnings are logged
  const Doc doc = adf::load(path, "colour file", &diag);
  AdfColors colors;
  for (const auto& entry : doc.root) {
    if (!entry.second.IsMap()) continue;
    const std::string name = entry.first.as<std::string>();
    std::array<float, 4> rgba{};
    const char* keys[4] = {"r", "g", "b", "a"};
    for (int i = 0; i < 4; ++i) {
      const YAML::Node v = entry.second[keys[i]];
      double value = 255;
      if (v) {
        // Written as hex (0xcd) or decimal; YAML's numbers do not read hex as a double.
        int n = 0;
        value = YAML::convert<int>::decode(v, n) ? n : adf::number(doc, v, name, keys[i]);
      }
      rgba[i] = static_cast<float>(value / 255.0);
    }
    colors.emplace(name, rgba);  // first wins, as YAML lookups do
  }
  return colors;
}

std::vector<AdfInputDevice> read_input_devices(const std::string& path,
                                               std::vector<AdfProblem>* warnings) {
  adf::Diagnostics diag;
  const Doc doc = adf::load(path, "input devices file", &diag);
  diag.repeated_entries(doc, {"input devices"});
  std::vector<AdfInputDevice> out;
  for (const auto& [id, n] : adf::listed(doc, "input devices")) {
    diag.unknown_keys(doc, id, n,
                      {"hardware name", "haptic gain", "controller gain", "deadband", "max force",
                       "max jerk", "workspace scaling", "orientation offset", "button mapping",
                       "visible", "visible size", "visible color", "simulated multibody",
                       "root link", "location", "enable joint control", "pair cameras", "cameras"});
    if (!n["hardware name"]) {
      diag.warn(doc.path, adf::at(n) + id + ": no 'hardware name'; the device is left out");
      continue;
    }
    AdfInputDevice d;
    d.identifier = id;
    d.hardware_name = adf::text(doc, n["hardware name"], id, "hardware name");
    if (const YAML::Node g = n["haptic gain"]) {
      d.haptic_gain_linear = adf::number_or(doc, g, "linear", id, 0.0);
      d.haptic_gain_angular = adf::number_or(doc, g, "angular", id, 0.0);
    }
    d.deadband = adf::number_or(doc, n, "deadband", id, d.deadband);
    d.max_force = adf::number_or(doc, n, "max force", id, d.max_force);
    d.max_jerk = adf::number_or(doc, n, "max jerk", id, d.max_jerk);
    d.workspace_scaling = adf::number_or(doc, n, "workspace scaling", id, d.workspace_scaling);
    if (const YAML::Node o = n["orientation offset"]) {
      d.orientation_offset =
          adf::rpy(adf::number_or(doc, o, "r", id, 0), adf::number_or(doc, o, "p", id, 0),
                   adf::number_or(doc, o, "y", id, 0));
    }
    if (const YAML::Node b = n["button mapping"]) {
      for (const auto& e : b) {
        d.buttons[e.first.as<std::string>()] =
            adf::integer(doc, e.second, id, "button mapping." + e.first.as<std::string>());
      }
    }
    if (n["visible"]) d.visible = adf::boolean(doc, n["visible"], id, "visible");
    d.visible_size = adf::number_or(doc, n, "visible size", id, d.visible_size);
    if (n["simulated multibody"]) {
      d.simulated_multibody = adf::resolve(
          doc.dir, adf::text(doc, n["simulated multibody"], id, "simulated multibody"));
    }
    if (n["root link"]) d.root_link = adf::text(doc, n["root link"], id, "root link");
    if (n["location"]) d.location = adf::frame(doc, n["location"], id, "location");
    if (n["enable joint control"]) {
      d.enable_joint_control =
          adf::boolean(doc, n["enable joint control"], id, "enable joint control");
    }
    const YAML::Node cams = n["pair cameras"] ? n["pair cameras"] : n["cameras"];
    if (cams) {
      d.pair_cameras = adf::as<std::vector<std::string>>(doc, cams, id, "pair cameras",
                                                         "a list of camera names");
    }
    out.push_back(std::move(d));
  }
  diag.not_applied(doc, "input devices", {"controller gain"},
                   "ambfplus has no controller from a device to a simulated multibody");
  diag.not_applied(doc, "input devices", {"visible color"}, "ambfplus draws no device marker");
  if (warnings != nullptr) {
    warnings->insert(warnings->end(), diag.warnings().begin(), diag.warnings().end());
  }
  return out;
}

void load_world_file(World& world, const std::string& path, const AdfColors& colors,
                     std::vector<AdfProblem>* warnings) {
  auto lock = world.lock_state();  // a real-time loop never steps a half-loaded file
  adf::Diagnostics diag;
  adf::Context ctx{&colors, &diag, ""};
  adf::yaml_checked(path, [&] { load_world(world, path, ctx); });
  adf::resolve_deferred(world, ctx);
  if (warnings != nullptr) {
    warnings->insert(warnings->end(), diag.warnings().begin(), diag.warnings().end());
  }
}

Model& load_model_file(World& world, const std::string& path, const AdfColors& colors,
                       std::vector<AdfProblem>* warnings) {
  auto lock = world.lock_state();  // a real-time loop never steps a half-loaded file
  adf::Diagnostics diag;
  adf::Context ctx{&colors, &diag, ""};
  Model& model =
      adf::yaml_checked(path, [&]() -> Model& { return adf::load_model(world, path, ctx); });
  adf::resolve_deferred(world, ctx);
  adf::warn_unresolved(world, ctx);
  if (warnings != nullptr) {
    warnings->insert(warnings->end(), diag.warnings().begin(), diag.warnings().end());
  }
  return model;
}

AdfReport load_launch(World& world, const std::string& path, const AdfLoadOptions& options) {
  auto lock = world.lock_state();  // a real-time loop never steps a half-loaded launch
  AdfReport report;
  report.launch = read_launch(path);
  const AdfLaunch& launch = report.launch;
  adf::Diagnostics diag;
  AdfColors colors;
  std::error_code ec;
  if (fs::is_regular_file(launch.colors, ec)) {
    colors = read_colors(launch.colors);
  } else {
    diag.warn(launch.file,
              "colour file " + launch.colors + " not found: colours by name fall back to grey");
  }
  adf::Context ctx{&colors, &diag, options.namespace_prefix};
  ctx.report_plugin_errors = !options.strict;
  ctx.report_environment_errors = !options.strict;
  const std::size_t models_before = world.models().size();
  if (options.load_world) {
    adf::yaml_checked(launch.world, [&] { load_world(world, launch.world, ctx); });
  }

  // One model failing is reported (or thrown, when strict) and leaves nothing behind. Objects
  // of earlier files waiting for a parent it declares are attached as soon as it is in.
  auto load_one = [&](const std::string& file, const std::string& what) {
    try {
      adf::yaml_checked(file, [&] { adf::load_model(world, file, ctx); });
    } catch (const Error& e) {
      if (options.strict) throw;
      diag.error(file, what + " not loaded: " + e.what());
      return;
    }
    adf::resolve_deferred(world, ctx);
  };
  std::vector<int> indices;
  if (options.indices) {
    indices = *options.indices;
  } else if (options.extra.empty()) {
    indices = {1};  // AMBF's default
  }
  for (int i : indices) {
    if (i < 0 || i >= static_cast<int>(launch.models.size())) {
      const std::string message = "launch index " + std::to_string(i) +
                                  " is out of range: the launch file lists " +
                                  std::to_string(launch.models.size()) + " model files";
      if (options.strict) throw ConfigError(launch.file, message);
      diag.error(launch.file, message);
      continue;
    }
    load_one(launch.models[i], "launch index " + std::to_string(i));
  }
  for (const std::string& file : options.extra) load_one(fs::absolute(file).string(), "extra file");

  if (fs::is_regular_file(launch.input_devices, ec)) {
    const std::vector<AdfInputDevice> devices =
        read_input_devices(launch.input_devices, &diag.warnings());
    for (int i : options.devices) {
      if (i < 0 || i >= static_cast<int>(devices.size())) {
        diag.error(launch.input_devices, "input device " + std::to_string(i) +
                                             " is out of range: the file lists " +
                                             std::to_string(devices.size()));
        continue;
      }
      const AdfInputDevice& d = devices[i];
      report.input_devices.push_back(d);
      if (!d.simulated_multibody.empty()) {
        load_one(d.simulated_multibody,
                 "simulated multibody of input device '" + d.identifier + "'");
      }
    }
  } else if (!options.devices.empty()) {
    diag.error(launch.input_devices, "input devices file not found: no devices set up");
  } else {
    diag.warn(launch.file, "input devices file " + launch.input_devices + " not found");
  }

  // Parents still missing now are missing for good (unless a later load brings them).
  adf::warn_unresolved(world, ctx);

  // Simulator plugins last, when the scene they see is complete: the launch file's, then those
  // given with the load (AMBF's --plugins).
  const PluginSite simulator = PluginSite::of(world.simulator());
  adf::load_plugins(launch.plugins, simulator, launch.file, "launch", ctx);
  for (const std::string& file : options.plugins) {
    adf::load_plugins({AdfPlugin{"", file, ""}}, simulator, "command line", "--plugins", ctx);
  }

  const std::vector<Model*> models = world.models();
  report.models.assign(models.begin() + static_cast<std::ptrdiff_t>(models_before), models.end());
  report.errors = diag.errors();
  report.warnings = diag.warnings();
  return report;
}

}  // namespace ambfplus
