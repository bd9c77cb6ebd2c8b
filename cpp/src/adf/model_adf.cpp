// Model files, the loader's core: the file's top level, names and namespaces, and the order in
// which the blocks' plans (one reader per block kind, model_blocks.h) are created, all or
// nothing, once every block has been read and every mesh found.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <optional>
#include <set>

#include "adf/model_blocks.h"
#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::adf {

Object* find_object(World& world, const std::string& ref, const std::string& ns,
                    const std::vector<std::pair<std::string, RigidBody*>>& own,
                    std::optional<ObjectKind> kind, std::string& why) {
  for (const auto& [id, body] : own) {
    if (id == ref || ns + id == ref) return body;
  }
  for (const auto& [id, body] : own) {
    if (body->name() == remove_spaces(ref)) return body;
  }
  // Within the file's namespace first (two namespaces may each have the name), then anywhere.
  std::vector<Object*> found = world.lookup(ns + ref, kind);
  if (found.empty()) found = world.lookup(ref, kind);
  if (!kind) {
    found.erase(std::remove_if(found.begin(), found.end(),
                               [](Object* o) { return o->kind() == ObjectKind::kJoint; }),
                found.end());
  }
  if (found.size() == 1) return found.front();
  const std::string what = kind ? object_kind_name(*kind) : "object";
  if (found.empty()) {
    why = "no " + what + " '" + ref + "' in the file or the world";
  } else {
    why = "'" + ref + "' matches " + std::to_string(found.size()) + " " + what + "s (" +
          found[0]->qualified_name() + ", " + found[1]->qualified_name() +
          (found.size() > 2 ? ", ..." : "") + ")";
  }
  return nullptr;
}

RigidBody* find_body(World& world, const std::string& ref, const std::string& ns,
                     const std::vector<std::pair<std::string, RigidBody*>>& own, std::string& why) {
  return static_cast<RigidBody*>(find_object(world, ref, ns, own, ObjectKind::kRigidBody, why));
}

std::string join_ns(const std::string& prefix, const std::string& base, const std::string& ns) {
  std::string out;
  if (ns.empty()) {
    out = base;
  } else if (ns.front() == '/') {
    out = prefix.empty()
              ? ns
              : (prefix.back() == '/' ? prefix.substr(0, prefix.size() - 1) : prefix) + ns;
  } else {
    out = base + ns;
  }
  if (!out.empty() && out.back() != '/') out += '/';
  return out;
}

std::string unique_name(const World& world, const std::string& ns, const std::string& name,
                        const std::string& file, const Model& loading) {
  const Object* taken = world.find(name_key(ns, name));
  if (taken == nullptr) return name;
  for (int n = 1;; ++n) {
    const std::string candidate = name + std::to_string(n);
    if (world.find(name_key(ns, candidate)) == nullptr) {
      if (&taken->model() == &loading) return candidate;  // the file's own repeat: warned
      log(LogLevel::kWarning, file + ": the world already has '" + name_key(ns, name) +
                                  "' (the same name in the same namespace): this one is named '" +
                                  name_key(ns, candidate) + "'");
      return candidate;
    }
  }
}

namespace {

// The warnings a model file's keys give before anything is read: unknown keys, repeated names,
// and keys AMBF reads that change nothing here (one warning each per file).
void warn_model_keys(const Doc& doc, Context& ctx) {
  // Top-level keys that are not AMBF's, nor blocks a list names, are reported.
  static const std::set<std::string> known = {"bodies",
                                              "soft bodies",
                                              "ghost objects",
                                              "joints",
                                              "sensors",
                                              "actuators",
                                              "cameras",
                                              "lights",
                                              "volumes",
                                              "vehicles",
                                              "drills",
                                              "high resolution path",
                                              "low resolution path",
                                              "namespace",
                                              "ignore inter-collision",
                                              "joint erp",
                                              "joint cfm",
                                              "plugins",
                                              "shaders",
                                              "gravity",
                                              "adf version"};
  ctx.diag->unknown_top_level(doc, known,
                              {"bodies", "soft bodies", "ghost objects", "joints", "sensors",
                               "actuators", "cameras", "lights", "volumes", "vehicles", "drills"});
  ctx.diag->repeated_entries(
      doc, {"bodies", "soft bodies", "ghost objects", "joints", "sensors", "actuators", "cameras",
            "lights", "volumes", "vehicles", "drills"});
  ctx.diag->repeated_names(doc, {"bodies", "soft bodies", "ghost objects", "joints", "sensors",
                                 "actuators", "cameras", "lights", "volumes"});
  for (const char* list : {"bodies", "ghost objects"}) {
    ctx.diag->not_applied(
        doc, list, {"controller", "controller output type"},
        "ambfplus has no body pose controller (set poses directly, or use joints)");
    ctx.diag->not_applied(
        doc, list, {"use material"},
        "a mesh takes its block's colour, and its material file's texture where it has one");
    ctx.diag->not_applied(doc, list, {"mesh remove duplicates"},
                          "a mesh's identical vertices are always merged");
  }
  ctx.diag->not_applied(doc, "joints", {"enable feedback"}, "joint wrenches are not measured");
  ctx.diag->not_applied(doc, "joints", {"enable motor"},
                        "a joint's motor is driven by its controller's commands");
  ctx.diag->not_applied(doc, "soft bodies",
                        {"linear gain", "angular gain", "inertial offset", "collision groups"},
                        "soft bodies have no controller, offset or collision groups here");
  ctx.diag->not_applied(doc, "soft bodies", {"gravity"},
                        "soft bodies fall with the world's gravity here");
  ctx.diag->not_applied(doc, "soft bodies", {"inertia", "controller", "controller output type"},
                        "a soft body's mass is spread over its nodes, and it has no controller");
  ctx.diag->not_applied(
      doc, "soft bodies",
      {"mesh remove duplicates", "shape", "compound shape", "geometry", "collision shape",
       "collision geometry", "collision offset", "compound collision shape", "collision mesh type"},
      "a soft body is built from its mesh alone");
}

// A model's `gravity` (AMBF): the gravity of each of its rigid bodies that has none of its own.
void apply_model_gravity(const Doc& doc, std::vector<BodyPlan>& bodies, Context& ctx) {
  const YAML::Node node = doc.root["gravity"];
  if (!node) return;
  const Eigen::Vector3d g = xyz(doc, node, "model", "gravity", Eigen::Vector3d::Zero());
  for (BodyPlan& body : bodies) {
    if (!body.spec.dynamics.gravity) body.spec.dynamics.gravity = g;
  }
  if (!listed(doc, "soft bodies").empty()) {
    ctx.diag->warn(doc.path, at(node) +
                                 "the model's 'gravity' is applied to its rigid bodies only; "
                                 "its soft bodies fall with the world's gravity");
  }
}

}  // namespace

Model& load_model(World& world, const std::string& path, Context& ctx) {
  const Doc doc = load(path, "model file", ctx.diag);
  const YAML::Node& root = doc.root;
  const std::string where = "model";
  warn_model_keys(doc, ctx);
  const std::string model_ns =
      join_ns(ctx.prefix, world.name_space(),
              root["namespace"] ? text(doc, root["namespace"], where, "namespace") : "");
  const std::string hr = root["high resolution path"] ? text(doc, root["high resolution path"],
                                                             where, "high resolution path")
                                                      : "";
  const std::string lr = root["low resolution path"]
                             ? text(doc, root["low resolution path"], where, "low resolution path")
                             : "";
  const bool ignore_inter_collision =
      root["ignore inter-collision"] &&
      boolean(doc, root["ignore inter-collision"], where, "ignore inter-collision");

  // Everything is read (and every mesh found) before anything is created.
  std::vector<BodyPlan> bodies;
  for (const auto& [id, block] : listed(doc, "bodies")) {
    try {
      bodies.push_back(plan_body(doc, hr, lr, model_ns, id, block, ctx));
    } catch (const AssetNotFound& e) {
      // A world's environment goes on without a body whose mesh is missing (AMBF's scope).
      if (!ctx.skip_missing_meshes) throw;
      ctx.diag->error(doc.path, at(block) + id + ": left out: " + e.what());
    }
  }
  apply_model_gravity(doc, bodies, ctx);
  // Ghost objects: a body's keys (no mass) and a `parent` they ride on.
  struct GhostPlan {
    BodyPlan body;
    std::string parent;
  };
  std::vector<GhostPlan> ghosts;
  for (const auto& [id, block] : listed(doc, "ghost objects")) {
    YAML::Node keys = YAML::Clone(block);
    std::string parent;
    if (block["parent"]) parent = text(doc, block["parent"], id, "parent");
    keys.remove("parent");
    if (!keys["mass"]) keys["mass"] = 0.0;  // a ghost has none; no warning about it
    ghosts.push_back({plan_body(doc, hr, lr, model_ns, id, keys, ctx), parent});
  }
  std::vector<JointPlan> joints;
  for (const auto& [id, block] : listed(doc, "joints")) {
    joints.push_back(plan_joint(doc, model_ns, id, block, ctx));
  }
  std::vector<std::pair<std::string, SoftBodySpec>> softs;
  std::vector<std::vector<AdfPlugin>> soft_plugins;
  for (const auto& [id, block] : listed(doc, "soft bodies")) {
    softs.emplace_back(id, plan_soft_body(doc, lr, hr, id, block, ctx));
    soft_plugins.push_back(read_plugins(doc, block["plugins"], id));
  }
  std::vector<SensorPlan> sensors;
  for (const bool actuator : {false, true}) {
    for (const auto& [id, block] : listed(doc, actuator ? "actuators" : "sensors")) {
      if (auto p = plan_sensor(doc, model_ns, actuator, id, block, ctx)) sensors.push_back(*p);
    }
  }
  if (!listed(doc, "vehicles").empty()) {
    ctx.diag->warn(doc.path, at(root["vehicles"]) + "'vehicles' are not loaded yet");
  }
  const std::optional<ShaderSpec> model_shader =
      read_shader(doc, root["shaders"], where, "shaders", ctx);
  const std::vector<AdfPlugin> model_plugins = read_plugins(doc, root["plugins"], where);
  const bool has_volumes = static_cast<bool>(root["volumes"]);
  std::vector<AdfVolumeBlock> volumes;
  std::vector<AdfDrillBlock> drills;
  if (has_volumes) volumes = read_adf_volumes(path);
  if (root["drills"]) drills = read_adf_drills(path);

  std::string model_name = unique_model_name(world, fs::path(path).stem().string());
  Model& model = world.add_model(model_name);
  model.set_shader(model_shader);
  std::string current = "model";
  try {
    std::vector<std::pair<std::string, RigidBody*>> own;
    std::vector<ObjectPlugins> object_plugins;
    for (BodyPlan& b : bodies) {
      current = b.id;
      b.spec.name = unique_name(world, b.ns, b.spec.name, doc.path, model);
      const InNameSpace in_ns(model, b.ns);
      RigidBody& body = model.add_body(b.spec);
      body.set_identifier(b.id);
      own.emplace_back(b.id, &body);
      if (!b.plugins.empty()) object_plugins.push_back({&body, b.id, b.plugins});
    }
    // The model-wide flag: its bodies pass through one another (joints have their own).
    if (ignore_inter_collision) {
      for (std::size_t i = 0; i < own.size(); ++i) {
        for (std::size_t k = i + 1; k < own.size(); ++k) {
          own[i].second->ignore_collisions_with(*own[k].second);
        }
      }
    }
    for (std::size_t i = 0; i < softs.size(); ++i) {
      auto& [id, spec] = softs[i];
      current = id;
      spec.name = unique_name(world, model_ns, spec.name, doc.path, model);
      const InNameSpace in_ns(model, model_ns);
      SoftBody& soft = model.add_soft_body(spec);
      soft.set_identifier(id);
      if (!soft_plugins[i].empty()) object_plugins.push_back({&soft, id, soft_plugins[i]});
    }
    // Joints, sensors and actuators whose bodies are not in the world yet are made when a
    // later file brings them.
    Model* target = &model;
    for (JointPlan& j : joints) {
      current = j.id;
      const bool now = [&] {
        std::string why;
        return find_body(world, j.parent, model_ns, own, why) != nullptr &&
               find_body(world, j.child, model_ns, own, why) != nullptr;
      }();
      // A joint made now has its plugins loaded with its file's; one made later when the load
      // that brought its bodies is done.
      std::vector<ObjectPlugins>* sink = now ? &object_plugins : nullptr;
      auto make = [target, plan = j, model_ns, own, sink, file = doc.path](World& w) {
        std::string why;
        RigidBody* parent = find_body(w, plan.parent, model_ns, own, why);
        RigidBody* child = find_body(w, plan.child, model_ns, own, why);
        if (parent == nullptr || child == nullptr) return false;
        JointSpec spec = plan.spec;
        spec.parent = parent;
        spec.child = child;
        spec.parent_pivot *= parent->shape().scale;
        spec.child_pivot *= child->shape().scale;
        spec.name = unique_name(w, plan.ns, spec.name, file, *target);
        const InNameSpace in_ns(*target, plan.ns);
        Joint& joint = target->add_joint(spec);
        joint.set_identifier(plan.id);
        if (plan.six_dof) set_six_dof_axes(joint, *plan.six_dof);
        if (plan.cone)
          set_cone_twist_limits(joint, (*plan.cone)[0], (*plan.cone)[1], (*plan.cone)[2]);
        if (!plan.plugins.empty()) {
          ObjectPlugins plugins{&joint, plan.id, plan.plugins};
          if (sink != nullptr) {
            sink->push_back(std::move(plugins));
          } else {
            load_plugins_later(std::move(plugins), file);
          }
        }
        return true;
      };
      now_or_later(
          model, doc.path,
          [&] {
            std::string why_parent, why_child;
            const bool has_parent =
                find_body(world, j.parent, model_ns, own, why_parent) != nullptr;
            find_body(world, j.child, model_ns, own, why_child);
            return at(j.block) + j.id +
                   ": joint left out: " + (has_parent ? why_child : why_parent) +
                   " (made if a later load brings it)";
          },
          make);
    }
    for (SensorPlan& p : sensors) {
      current = p.id;
      std::vector<ObjectPlugins>* sink = [&] {
        std::string why;
        return find_body(world, p.parent, model_ns, own, why) != nullptr ? &object_plugins
                                                                         : nullptr;
      }();
      auto make = [target, plan = p, model_ns, own, sink, file = doc.path](World& w) {
        std::string why;
        RigidBody* parent = find_body(w, plan.parent, model_ns, own, why);
        if (parent == nullptr) return false;
        Object* made = nullptr;
        if (plan.actuator) {
          ConstraintActuatorSpec spec = plan.act;
          spec.parent = parent;
          spec.name = unique_name(w, plan.ns, spec.name, file, *target);
          const InNameSpace in_ns(*target, plan.ns);
          made = &target->add_actuator(spec);
        } else {
          ProximitySensorSpec spec = plan.sensor;
          spec.parent = parent;
          spec.name = unique_name(w, plan.ns, spec.name, file, *target);
          const InNameSpace in_ns(*target, plan.ns);
          made = &target->add_sensor(spec);
        }
        made->set_identifier(plan.id);
        if (!plan.plugins.empty()) {
          ObjectPlugins plugins{made, plan.id, plan.plugins};
          if (sink != nullptr) {
            sink->push_back(std::move(plugins));
          } else {
            load_plugins_later(std::move(plugins), file);
          }
        }
        return true;
      };
      now_or_later(
          model, doc.path,
          [&] {
            std::string why;
            find_body(world, p.parent, model_ns, own, why);
            return at(p.block) + p.id + ": left out: " + why + " (made if a later load brings it)";
          },
          make);
    }
    for (GhostPlan& g : ghosts) {
      current = g.body.id;
      g.body.spec.name = unique_name(world, g.body.ns, g.body.spec.name, doc.path, model);
      const InNameSpace in_ns(model, g.body.ns);
      RigidBody& ghost = add_ghost(model, g.body.spec);
      ghost.set_identifier(g.body.id);
      if (!g.body.plugins.empty()) object_plugins.push_back({&ghost, g.body.id, g.body.plugins});
      attach_when_found(model, doc.path, ghost, g.body.id, g.parent, g.body.ns, own,
                        Eigen::Isometry3d(g.body.spec.pose));
    }
    current = "cameras and lights";
    add_cameras_and_lights(model, doc, model_ns, ctx, own, object_plugins);
    current = "volumes";
    if (has_volumes || !drills.empty()) {
      const std::vector<Volume*> made =
          add_adf_volumes(model, path, "", volumes, drills, model_ns, own);
      for (std::size_t i = 0; i < made.size(); ++i) {
        if (!volumes[i].plugins.empty()) {
          object_plugins.push_back({made[i], volumes[i].identifier, volumes[i].plugins});
        }
      }
    }
    // Plugins once the model is built: its objects' in creation order, then its own.
    load_plugins(object_plugins, doc.path, ctx);
    load_plugins(model_plugins, PluginSite::of(model), doc.path, where, ctx);
  } catch (const AssetNotFound&) {
    world.remove_model(model);
    throw;
  } catch (const ConfigError&) {
    world.remove_model(model);
    throw;
  } catch (const PluginError&) {
    world.remove_model(model);
    throw;
  } catch (const std::exception& e) {
    world.remove_model(model);
    throw ConfigError(doc.path, current + ": " + e.what());
  }
  return model;
}

std::string unique_model_name(const World& world, const std::string& base) {
  auto taken = [&](const std::string& name) {
    for (Model* m : world.models()) {
      if (m->name() == name) return true;
    }
    return false;
  };
  if (!taken(base)) return base;
  for (int n = 1;; ++n) {
    if (!taken(base + std::to_string(n))) return base + std::to_string(n);
  }
}

}  // namespace ambfplus::adf
