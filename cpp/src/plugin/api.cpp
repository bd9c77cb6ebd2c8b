// The engine's C API for plugins (ambfplus/plugin/api.h): handles and plain data over the scene.

#include "ambfplus/plugin/api.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"
#include "plugin/plugin_options.h"

namespace ambfplus {
namespace {

thread_local std::string g_last_error;

World& world_of(const AmbfplusWorld* w) {
  if (w == nullptr) throw ArgumentError("no world (a null AmbfplusWorld)");
  return *reinterpret_cast<World*>(const_cast<AmbfplusWorld*>(w));
}

Object& object_of(const AmbfplusWorld* w, AmbfplusId id) {
  World& world = world_of(w);
  Object* o = world.object_with_id(id);
  if (o == nullptr) {
    throw ArgumentError("world '" + world.name() + "' has no object with id " + std::to_string(id));
  }
  return *o;
}

template <typename T>
T& object_as(const AmbfplusWorld* w, AmbfplusId id, ObjectKind kind) {
  Object& o = object_of(w, id);
  if (o.kind() != kind) {
    throw ArgumentError("'" + o.name() + "' is a " + object_kind_name(o.kind()) + ", not a " +
                        object_kind_name(kind));
  }
  return static_cast<T&>(o);
}

// Runs a call, turning an exception into fallback and the thread's last error.
template <typename Result, typename Call>
Result guarded(Result fallback, const Call& call) {
  try {
    g_last_error.clear();
    return call();
  } catch (const std::exception& e) {
    g_last_error = e.what();
  } catch (...) {
    g_last_error = "an exception of unknown type";
  }
  return fallback;
}

Eigen::Isometry3d pose_from(const double* m, const Object& object, std::string_view role = {}) {
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix(r, c) = m[4 * r + c];
  return checked_pose(matrix, object, role);
}

void pose_to(const Eigen::Isometry3d& pose, double* m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[4 * r + c] = pose.matrix()(r, c);
}

// A property of one kind of object: its values, and how to set them (null: read-only).
struct Property {
  std::function<std::vector<double>(Object&)> get;
  std::function<void(Object&, const std::vector<double>&)> set;
};

std::vector<double> values_of(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d vector3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }
std::vector<double> pose_values(const Eigen::Isometry3d& pose) {
  std::vector<double> out(16);
  pose_to(pose, out.data());
  return out;
}

void want(const std::string& what, const std::vector<double>& v, std::size_t n) {
  if (v.size() != n) {
    throw ArgumentError(what + " takes " + std::to_string(n) + " values, got " +
                        std::to_string(v.size()));
  }
  for (double x : v) {
    if (!std::isfinite(x)) throw ArgumentError(what + " must be finite");
  }
}

bool flag(double v) { return v != 0.0; }

using Table = std::map<std::string, Property>;

Table body_properties() {
  auto body = [](Object& o) -> RigidBody& { return static_cast<RigidBody&>(o); };
  Table t;
  t["color"] = {[=](Object& o) {
                  const auto& c = body(o).material().color;
                  return std::vector<double>(c.begin(), c.end());
                },
                [=](Object& o, const std::vector<double>& v) {
                  want("color", v, 4);
                  Material m = body(o).material();
                  for (int i = 0; i < 4; ++i) m.color[i] = static_cast<float>(v[i]);
                  body(o).set_material(m);
                }};
  t["visible"] = {[=](Object& o) { return std::vector<double>{body(o).material().visible * 1.0}; },
                  [=](Object& o, const std::vector<double>& v) {
                    want("visible", v, 1);
                    Material m = body(o).material();
                    m.visible = flag(v[0]);
                    body(o).set_material(m);
                  }};
  t["kinematic"] = {
      [=](Object& o) { return std::vector<double>{body(o).dynamics().kinematic * 1.0}; },
      [=](Object& o, const std::vector<double>& v) {
        want("kinematic", v, 1);
        body(o).set_kinematic(flag(v[0]));
      }};
  t["mass"] = {[=](Object& o) { return std::vector<double>{body(o).mass()}; }, nullptr};
  t["force"] = {[=](Object& o) { return values_of(body(o).force()); },
                [=](Object& o, const std::vector<double>& v) {
                  want("force", v, 3);
                  body(o).set_force(vector3(v));
                }};
  t["torque"] = {[=](Object& o) { return values_of(body(o).torque()); },
                 [=](Object& o, const std::vector<double>& v) {
                   want("torque", v, 3);
                   body(o).set_torque(vector3(v));
                 }};
  t["linear_velocity"] = {[=](Object& o) { return values_of(body(o).linear_velocity()); },
                          [=](Object& o, const std::vector<double>& v) {
                            want("linear_velocity", v, 3);
                            body(o).set_linear_velocity(vector3(v));
                          }};
  t["angular_velocity"] = {[=](Object& o) { return values_of(body(o).angular_velocity()); },
                           [=](Object& o, const std::vector<double>& v) {
                             want("angular_velocity", v, 3);
                             body(o).set_angular_velocity(vector3(v));
                           }};
  return t;
}

Table joint_properties() {
  auto joint = [](Object& o) -> Joint& { return static_cast<Joint&>(o); };
  Table t;
  t["position"] = {[=](Object& o) { return std::vector<double>{joint(o).position()}; }, nullptr};
  t["velocity"] = {[=](Object& o) { return std::vector<double>{joint(o).velocity()}; }, nullptr};
  t["effort"] = {[=](Object& o) { return std::vector<double>{joint(o).effort()}; }, nullptr};
  t["position_command"] = {nullptr, [=](Object& o, const std::vector<double>& v) {
                             want("position_command", v, 1);
                             joint(o).set_position(v[0]);
                           }};
  t["velocity_command"] = {nullptr, [=](Object& o, const std::vector<double>& v) {
                             want("velocity_command", v, 1);
                             joint(o).set_velocity(v[0]);
                           }};
  t["effort_command"] = {nullptr, [=](Object& o, const std::vector<double>& v) {
                           want("effort_command", v, 1);
                           joint(o).set_effort(v[0]);
                         }};
  return t;
}

Table drill_properties() {
  auto drill = [](Object& o) -> Drill& { return static_cast<Drill&>(o); };
  auto per_cursor = [=](Object& o, const std::function<Eigen::Vector3d(Drill&, int)>& of) {
    std::vector<double> out;
    for (int i = 0; i < drill(o).cursor_count(); ++i) {
      const Eigen::Vector3d p = of(drill(o), i);
      out.insert(out.end(), {p.x(), p.y(), p.z()});
    }
    return out;
  };
  Table t;
  t["goal"] = {[=](Object& o) { return pose_values(drill(o).goal()); },
               [=](Object& o, const std::vector<double>& v) {
                 want("goal", v, 16);
                 drill(o).set_goal(pose_from(v.data(), o, "goal"));
               }};
  t["on"] = {[=](Object& o) { return std::vector<double>{drill(o).on() * 1.0}; },
             [=](Object& o, const std::vector<double>& v) {
               want("on", v, 1);
               drill(o).set_on(flag(v[0]));
             }};
  t["speed"] = {[=](Object& o) { return std::vector<double>{drill(o).speed()}; },
                [=](Object& o, const std::vector<double>& v) {
                  want("speed", v, 1);
                  drill(o).set_speed(v[0]);
                }};
  t["burr"] = {[=](Object& o) { return std::vector<double>{1.0 * drill(o).burr()}; },
               [=](Object& o, const std::vector<double>& v) {
                 want("burr", v, 1);
                 drill(o).set_burr(static_cast<int>(std::lround(v[0])));
               }};
  t["burr_diameters"] = {[=](Object& o) { return drill(o).spec().burr_diameters; }, nullptr};
  t["burr_radius"] = {[=](Object& o) { return std::vector<double>{drill(o).burr_radius()}; },
                      nullptr};
  t["cursor_count"] = {
      [=](Object& o) { return std::vector<double>{1.0 * drill(o).cursor_count()}; }, nullptr};
  t["cursor_radii"] = {[=](Object& o) {
                         std::vector<double> out;
                         for (int i = 0; i < drill(o).cursor_count(); ++i) {
                           out.push_back(drill(o).cursor_radius(i));
                         }
                         return out;
                       },
                       nullptr};
  t["cursor_proxies"] = {
      [=](Object& o) { return per_cursor(o, [](Drill& d, int i) { return d.cursor_proxy(i); }); },
      nullptr};
  t["cursor_goals"] = {
      [=](Object& o) { return per_cursor(o, [](Drill& d, int i) { return d.cursor_goal(i); }); },
      nullptr};
  t["meshes_follow_goal"] = {
      [=](Object& o) { return std::vector<double>{drill(o).meshes_follow_goal() * 1.0}; },
      [=](Object& o, const std::vector<double>& v) {
        want("meshes_follow_goal", v, 1);
        drill(o).set_meshes_follow_goal(flag(v[0]));
      }};
  t["voxels_per_step"] = {[=](Object& o) {
                            const auto& n = drill(o).spec().voxels_per_step;
                            return std::vector<double>(n.begin(), n.end());
                          },
                          [=](Object& o, const std::vector<double>& v) {
                            want("voxels_per_step", v, drill(o).spec().voxels_per_step.size());
                            for (std::size_t i = 0; i < v.size(); ++i) {
                              drill(o).set_voxels_per_step(static_cast<int>(i),
                                                           static_cast<int>(std::lround(v[i])));
                            }
                          }};
  t["force"] = {[=](Object& o) { return values_of(drill(o).force()); }, nullptr};
  t["total_force"] = {[=](Object& o) { return values_of(drill(o).total_force()); }, nullptr};
  t["removal"] = {
      [=](Object& o) {
        return std::vector<double>{drill(o).spec().removal == RemovalMode::kCompatible ? 1.0 : 0.0};
      },
      [=](Object& o, const std::vector<double>& v) {
        want("removal", v, 1);
        drill(o).set_removal_mode(flag(v[0]) ? RemovalMode::kCompatible : RemovalMode::kPhysical);
      }};
  return t;
}

Table camera_properties() {
  auto camera = [](Object& o) -> Camera& { return static_cast<Camera&>(o); };
  Table t;
  t["fov_y"] = {[=](Object& o) { return std::vector<double>{camera(o).fov_y()}; },
                [=](Object& o, const std::vector<double>& v) {
                  want("fov_y", v, 1);
                  camera(o).set_fov_y(v[0]);
                }};
  t["size"] = {[=](Object& o) {
                 return std::vector<double>{1.0 * camera(o).width(), 1.0 * camera(o).height()};
               },
               nullptr};
  t["intrinsics"] = {[=](Object& o) {
                       const Eigen::Matrix3d k = camera(o).intrinsics();
                       std::vector<double> out;
                       for (int r = 0; r < 3; ++r)
                         for (int c = 0; c < 3; ++c) out.push_back(k(r, c));
                       return out;
                     },
                     nullptr};
  return t;
}

const Property& property(Object& o, const std::string& name) {
  static const std::map<ObjectKind, Table> kTables = {{ObjectKind::kRigidBody, body_properties()},
                                                      {ObjectKind::kJoint, joint_properties()},
                                                      {ObjectKind::kDrill, drill_properties()},
                                                      {ObjectKind::kCamera, camera_properties()}};
  const auto table = kTables.find(o.kind());
  if (table != kTables.end()) {
    const auto it = table->second.find(name);
    if (it != table->second.end()) return it->second;
  }
  std::string known = "pose";
  if (table != kTables.end()) {
    for (const auto& [key, p] : table->second) known += ", " + key;
  }
  throw ArgumentError(std::string(object_kind_name(o.kind())) + " '" + o.name() +
                      "' has no property '" + name + "': it has " + known);
}

}  // namespace
}  // namespace ambfplus

using ambfplus::ArgumentError;
using ambfplus::guarded;

extern "C" {

const char* ambfplus_last_error(void) { return ambfplus::g_last_error.c_str(); }

void ambfplus_log(int level, const char* message) {
  ambfplus::log(static_cast<ambfplus::LogLevel>(level), message != nullptr ? message : "");
}

void ambfplus_world_lock(const AmbfplusWorld* world) {
  guarded(0, [&] {
    ambfplus::world_of(world).state_mutex().lock();
    return 0;
  });
}

void ambfplus_world_unlock(const AmbfplusWorld* world) {
  guarded(0, [&] {
    ambfplus::world_of(world).state_mutex().unlock();
    return 0;
  });
}

double ambfplus_world_time(const AmbfplusWorld* world) {
  return guarded(0.0, [&] { return ambfplus::world_of(world).time(); });
}

int64_t ambfplus_world_step_index(const AmbfplusWorld* world) {
  return guarded(int64_t{-1}, [&] { return ambfplus::world_of(world).step_index(); });
}

double ambfplus_world_time_step(const AmbfplusWorld* world) {
  return guarded(0.0, [&] { return ambfplus::world_of(world).time_step(); });
}

const char* ambfplus_world_name(const AmbfplusWorld* world) {
  return guarded<const char*>(nullptr, [&] { return ambfplus::world_of(world).name().c_str(); });
}

int ambfplus_world_argument_count(const AmbfplusWorld* world) {
  return guarded(-1, [&] {
    return static_cast<int>(ambfplus::world_of(world).simulator().arguments().size());
  });
}

const char* ambfplus_world_argument(const AmbfplusWorld* world, int index) {
  return guarded<const char*>(nullptr, [&] {
    const auto& args = ambfplus::world_of(world).simulator().arguments();
    if (index < 0 || index >= static_cast<int>(args.size())) {
      throw ArgumentError("argument " + std::to_string(index) + " of " +
                          std::to_string(args.size()));
    }
    return args[static_cast<std::size_t>(index)].c_str();
  });
}

int ambfplus_world_object_count(const AmbfplusWorld* world) {
  return guarded(-1, [&] { return static_cast<int>(ambfplus::world_of(world).objects().size()); });
}

AmbfplusId ambfplus_world_object(const AmbfplusWorld* world, int index) {
  return guarded<AmbfplusId>(0, [&] {
    const std::vector<ambfplus::Object*> objects = ambfplus::world_of(world).objects();
    if (index < 0 || index >= static_cast<int>(objects.size())) {
      throw ArgumentError("object " + std::to_string(index) + " of " +
                          std::to_string(objects.size()));
    }
    return objects[static_cast<std::size_t>(index)]->id();
  });
}

AmbfplusId ambfplus_world_find(const AmbfplusWorld* world, const char* name, int kind) {
  return guarded<AmbfplusId>(0, [&] {
    ambfplus::Object* o = ambfplus::world_of(world).find(name != nullptr ? name : "");
    if (o == nullptr || (kind >= 0 && static_cast<int>(o->kind()) != kind)) {
      throw ArgumentError(std::string("no object named '") + (name ? name : "") + "'");
    }
    return o->id();
  });
}

int ambfplus_world_lookup(const AmbfplusWorld* world, const char* query, int kind, AmbfplusId* ids,
                          int capacity) {
  return guarded(-1, [&] {
    std::optional<ambfplus::ObjectKind> want;
    if (kind >= 0) want = static_cast<ambfplus::ObjectKind>(kind);
    const auto found =
        ambfplus::name_candidates(ambfplus::world_of(world), query != nullptr ? query : "", want);
    for (int i = 0; i < capacity && i < static_cast<int>(found.size()); ++i) {
      ids[i] = found[static_cast<std::size_t>(i)]->id();
    }
    return static_cast<int>(found.size());
  });
}

AmbfplusId ambfplus_world_add(AmbfplusWorld* world, const char* model, const char* kind,
                              const char* name, const AmbfplusOption* options, int count) {
  return guarded<AmbfplusId>(0, [&] {
    ambfplus::World& w = ambfplus::world_of(world);
    ambfplus::Model* target = &w.default_model();
    if (model != nullptr && *model != '\0') {
      target = nullptr;
      for (ambfplus::Model* m : w.models()) {
        if (m->name() == model) target = m;
      }
      if (target == nullptr) target = &w.add_model(model);
    }
    const std::string what = kind != nullptr ? kind : "";
    const std::string called = name != nullptr ? name : "";
    return ambfplus::plugin::add_object(*target, what, called,
                                        ambfplus::plugin::to_options(options, count))
        .id();
  });
}

int ambfplus_ghost_overlaps(const AmbfplusWorld* world, AmbfplusId ghost, AmbfplusId* ids,
                            int capacity) {
  return guarded(-1, [&] {
    const auto& body =
        ambfplus::object_as<ambfplus::RigidBody>(world, ghost, ambfplus::ObjectKind::kRigidBody);
    const std::vector<ambfplus::Object*> found = ambfplus::ghost_overlaps(body);
    for (int i = 0; i < capacity && i < static_cast<int>(found.size()); ++i) {
      ids[i] = found[static_cast<std::size_t>(i)]->id();
    }
    return static_cast<int>(found.size());
  });
}

int ambfplus_object_kind(const AmbfplusWorld* world, AmbfplusId object) {
  return guarded(-1, [&] { return static_cast<int>(ambfplus::object_of(world, object).kind()); });
}

const char* ambfplus_object_name(const AmbfplusWorld* world, AmbfplusId object) {
  return guarded<const char*>(nullptr,
                              [&] { return ambfplus::object_of(world, object).name().c_str(); });
}

const char* ambfplus_object_model(const AmbfplusWorld* world, AmbfplusId object) {
  return guarded<const char*>(
      nullptr, [&] { return ambfplus::object_of(world, object).model().name().c_str(); });
}

int ambfplus_object_pose(const AmbfplusWorld* world, AmbfplusId object, double pose[16]) {
  return guarded(-1, [&] {
    ambfplus::pose_to(ambfplus::object_of(world, object).pose(), pose);
    return 0;
  });
}

int ambfplus_object_set_pose(AmbfplusWorld* world, AmbfplusId object, const double pose[16]) {
  return guarded(-1, [&] {
    ambfplus::Object& o = ambfplus::object_of(world, object);
    o.set_pose(ambfplus::pose_from(pose, o));
    return 0;
  });
}

int ambfplus_object_get(const AmbfplusWorld* world, AmbfplusId object, const char* property,
                        double* values, int capacity) {
  return guarded(-1, [&] {
    ambfplus::Object& o = ambfplus::object_of(world, object);
    const std::string name = property != nullptr ? property : "";
    const std::vector<double> v = name == "pose" ? ambfplus::pose_values(o.pose()) : [&] {
      const auto& p = ambfplus::property(o, name);
      if (!p.get) {
        throw ArgumentError("'" + name + "' can only be set");
      }
      return p.get(o);
    }();
    for (int i = 0; i < capacity && i < static_cast<int>(v.size()); ++i) values[i] = v[i];
    return static_cast<int>(v.size());
  });
}

int ambfplus_object_set(AmbfplusWorld* world, AmbfplusId object, const char* property,
                        const double* values, int count) {
  return guarded(-1, [&] {
    ambfplus::Object& o = ambfplus::object_of(world, object);
    const std::string name = property != nullptr ? property : "";
    const std::vector<double> v(values, values + std::max(count, 0));
    if (name == "pose") {
      ambfplus::want("pose", v, 16);
      o.set_pose(ambfplus::pose_from(v.data(), o));
      return 0;
    }
    const auto& p = ambfplus::property(o, name);
    if (!p.set) throw ArgumentError("'" + name + "' of '" + o.name() + "' is read-only");
    p.set(o, v);
    return 0;
  });
}

int ambfplus_object_attach(AmbfplusWorld* world, AmbfplusId object, AmbfplusId parent,
                           const double local[16]) {
  return guarded(-1, [&] {
    ambfplus::Object& o = ambfplus::object_of(world, object);
    if (parent == 0) {
      o.attach_to(nullptr, Eigen::Isometry3d::Identity());
      return 0;
    }
    ambfplus::Object& p = ambfplus::object_of(world, parent);
    const Eigen::Isometry3d offset = local != nullptr
                                         ? ambfplus::pose_from(local, o, "local")
                                         : Eigen::Isometry3d(p.pose().inverse() * o.pose());
    if (p.kind() == ambfplus::ObjectKind::kDrill && o.kind() == ambfplus::ObjectKind::kRigidBody) {
      static_cast<ambfplus::Drill&>(p).attach(static_cast<ambfplus::RigidBody&>(o), offset);
    } else {
      o.attach_to(&p, offset);
    }
    return 0;
  });
}

int ambfplus_volume_name_labels(AmbfplusWorld* world, AmbfplusId volume, const char* label_file) {
  return guarded(-1, [&] {
    auto& v = ambfplus::object_as<ambfplus::Volume>(world, volume, ambfplus::ObjectKind::kVolume);
    v.data()->name_labels_from(ambfplus::read_label_table(label_file != nullptr ? label_file : ""));
    return 0;
  });
}

int ambfplus_volume_mark_critical(AmbfplusWorld* world, AmbfplusId volume) {
  return guarded(-1, [&] {
    auto& v = ambfplus::object_as<ambfplus::Volume>(world, volume, ambfplus::ObjectKind::kVolume);
    v.data()->mark_critical_structures();
    return 0;
  });
}

}  // extern "C"
