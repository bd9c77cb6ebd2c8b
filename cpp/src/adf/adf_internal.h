#pragma once

// What the ADF readers share inside the engine.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "adf/adf_yaml.h"
#include "ambfplus/adf/adf.h"
#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/shader_spec.h"

namespace ambfplus {

class Model;
class Object;
class RigidBody;
class World;
struct PluginSite;

namespace adf {

/// What a load carries from file to file.
struct Context {
  const AdfColors* colors = nullptr;
  Diagnostics* diag = nullptr;
  std::string prefix;  ///< AMBF's --ns
  /// A plugin that fails is an error of the load report (a non-strict launch) instead of a
  /// PluginError.
  bool report_plugin_errors = false;
  /// A launch that is not strict: a world's environment that cannot load is an error of the
  /// report and the rest of the world loads (AMBF's scope), instead of an exception.
  bool report_environment_errors = false;
  /// While loading a world's environment without strictness: a body whose mesh is missing is
  /// left out (an error of the report) and the rest of the file loads, as in AMBF.
  bool skip_missing_meshes = false;
};

/// Finishes the links waiting for objects that have now appeared; an error doing so is an
/// error of the report (or thrown when ctx reports no errors).
void resolve_deferred(World& world, Context& ctx);

/// Warns of every link still waiting (once everything a load asked for is in the world).
void warn_unresolved(const World& world, Context& ctx);

/// The `plugins: [{name, filename, path}]` list under a block, `path` made absolute.
std::vector<AdfPlugin> read_plugins(const Doc& doc, const YAML::Node& list,
                                    const std::string& where);

/// The plugins an object's block declares, loaded once its whole file is built.
struct ObjectPlugins {
  Object* object = nullptr;
  std::string where;  ///< its block, "BODY l1"
  std::vector<AdfPlugin> plugins;
};

/// Plugins of an object a deferred link made once a later file brought what it waited for:
/// the resolve_deferred that made it loads them when it is done, into that load's report.
void load_plugins_later(ObjectPlugins plugins, std::string file);

/// A `shaders: {path, vertex, fragment}` block (key names it in messages): `path` relative to
/// the file, the two files relative to `path`. A missing file is a warning and gives nullopt
/// (the engine's own shader draws).
std::optional<ShaderSpec> read_shader(const Doc& doc, const YAML::Node& block,
                                      const std::string& where, const std::string& key,
                                      Context& ctx);

/// Loads plugins declared in file (at `where`: "launch", "world", "model", "BODY l1") at
/// site. A failure throws PluginError naming the file, or with ctx.report_plugin_errors is an
/// error of the report; a plugin whose init() declines is a warning.
void load_plugins(const std::vector<AdfPlugin>& plugins, const PluginSite& site,
                  const std::string& file, const std::string& where, Context& ctx);
void load_plugins(const std::vector<ObjectPlugins>& objects, const std::string& file, Context& ctx);

/// A namespace as AMBF resolves it: absolute ones kept (after the prefix), relative ones
/// appended to base, none gives base; always ending in '/'.
std::string join_ns(const std::string& prefix, const std::string& base, const std::string& ns);

/// name, or name1, name2, ... : the first the world does not use (AMBF's duplicate loads).
/// While it lives, objects `model` makes are in namespace `ns` (Model::set_object_name_space);
/// the model's namespace before it is restored after.
class InNameSpace {
 public:
  InNameSpace(Model& model, std::string ns) : model_(model), before_(model.object_name_space()) {
    model_.set_object_name_space(std::move(ns));
  }
  ~InNameSpace() { model_.set_object_name_space(before_); }
  InNameSpace(const InNameSpace&) = delete;
  InNameSpace& operator=(const InNameSpace&) = delete;

 private:
  Model& model_;
  std::string before_;
};

/// `name` if its key in namespace `ns` is free; else the first free `name` + n, with a warning
/// naming `file` when the name is taken by another model's object (two blocks of one file with
/// one name have a warning of their own): nothing is renamed silently, and names in different
/// namespaces never clash.
std::string unique_name(const World& world, const std::string& ns, const std::string& name,
                        const std::string& file, const Model& loading);
std::string unique_model_name(const World& world, const std::string& base);

/// The `cameras` and `lights` a file lists, added to model; parents are looked up in `own`
/// (identifier, body) and then the world. The plugins their blocks declare go to plugins.
void add_cameras_and_lights(Model& model, const Doc& doc, const std::string& base_ns, Context& ctx,
                            const std::vector<std::pair<std::string, RigidBody*>>& own,
                            std::vector<ObjectPlugins>& plugins);

/// A model file, all or nothing.
Model& load_model(World& world, const std::string& path, Context& ctx);

/// Volumes (each from its slice stack) and then drills on them, added to model. A non-empty
/// labels file overrides the blocks' label tables. A volume's `parent` and a drill's volume
/// that the file lacks are looked up in own (the file's bodies), then the world under ns,
/// now or once a later file brings them.
std::vector<Volume*> add_adf_volumes(
    Model& model, const std::string& path, const std::string& labels,
    const std::vector<AdfVolumeBlock>& volumes, std::vector<AdfDrillBlock> drills,
    const std::string& ns = "", const std::vector<std::pair<std::string, RigidBody*>>& own = {});

}  // namespace adf
}  // namespace ambfplus
