#include "ambfplus/scene/names.h"

#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {
namespace {

constexpr ObjectKind kAllKinds[] = {
    ObjectKind::kRigidBody, ObjectKind::kJoint,      ObjectKind::kCamera,   ObjectKind::kLight,
    ObjectKind::kVolume,    ObjectKind::kDrill,      ObjectKind::kSoftBody, ObjectKind::kSensor,
    ObjectKind::kActuator,  ObjectKind::kInputDevice};

}  // namespace

std::string name_key(std::string_view name_space, std::string_view name) {
  std::string_view ns = name_space;
  if (ns.substr(0, kRootNameSpace.size()) == kRootNameSpace) {
    ns.remove_prefix(kRootNameSpace.size());
  } else if (ns == kRootNameSpace.substr(0, kRootNameSpace.size() - 1)) {
    ns = {};
  }
  while (!ns.empty() && ns.front() == '/') ns.remove_prefix(1);
  std::string out(ns);
  if (!out.empty() && out.back() != '/') out += '/';
  out += name;
  return out;
}

ObjectKind parse_object_kind(std::string_view name) {
  for (ObjectKind k : kAllKinds) {
    if (name == object_kind_name(k)) return k;
  }
  throw ArgumentError("unknown kind '" + std::string(name) +
                      "': expected body, joint, camera, light, volume, drill, soft body, "
                      "sensor, actuator or input device");
}

std::vector<Object*> name_candidates(const World& world, const std::string& name,
                                     std::optional<ObjectKind> kind) {
  std::vector<Object*> found = world.lookup(name, kind);
  if (found.size() > 1 && !kind) {
    std::vector<Object*> not_joints;
    for (Object* o : found) {
      if (o->kind() != ObjectKind::kJoint) not_joints.push_back(o);
    }
    if (not_joints.size() == 1) found = not_joints;
  }
  return found;
}

Object& resolve_name(const World& world, const std::string& name, std::optional<ObjectKind> kind) {
  const std::vector<Object*> found = name_candidates(world, name, kind);
  if (found.size() == 1) return *found.front();
  if (found.empty()) throw NotFound("no object named '" + name + "' in the world");
  std::string names;
  for (std::size_t i = 0; i < found.size() && i < 6; ++i) {
    names += (i ? ", " : "") + found[i]->key();
  }
  throw NotFound("'" + name + "' is ambiguous: it matches " + std::to_string(found.size()) +
                 " objects (" + names + (found.size() > 6 ? ", ..." : "") + ")");
}

}  // namespace ambfplus
