#pragma once

// Name resolution as AMBF's users expect it, in one place for the Python bindings and the plugin
// C API alike.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/object.h"

namespace ambfplus {

class World;

/// AMBF's root namespace: objects in it are keyed by their bare name.
inline constexpr std::string_view kRootNameSpace = "/ambf/env/";

/// The key of an object named `name` in namespace `name_space` (Object::key): the namespace
/// below kRootNameSpace, without leading slashes and ending in one, then the name.
/// name_key("/ambf/env/psm1/", "baselink") == "psm1/baselink"; name_key("/ambf/env/", "l1") ==
/// name_key("", "l1") == "l1".
AMBFPLUS_API std::string name_key(std::string_view name_space, std::string_view name);

/// The kind a user names ("body", "joint", "camera", ... as object_kind_name gives them).
/// Throws ArgumentError listing the names for one that is none of them.
AMBFPLUS_API ObjectKind parse_object_kind(std::string_view name);

/// The objects a name refers to, by AMBF's rules, optionally of one kind:
/// 1. World::lookup's tiers: a full name ("/ambf/env/psm1/l1"), then a key ("psm1/l1"), then a
///    bare name or identifier ("l1", "BODY l1"), then names containing it;
/// 2. when several match and no kind was asked for, joints are left out if that leaves one
///    (AMBF's clients find bodies, cameras and lights by name; joints only when asked for).
/// One result is a match; none or several are for the caller to report (resolve_name does).
AMBFPLUS_API std::vector<Object*> name_candidates(const World& world, const std::string& name,
                                                  std::optional<ObjectKind> kind = std::nullopt);

/// The one object a name refers to (name_candidates). Throws NotFound saying that nothing
/// matches, or that the name is ambiguous with the first matches' keys.
AMBFPLUS_API Object& resolve_name(const World& world, const std::string& name,
                                  std::optional<ObjectKind> kind = std::nullopt);

}  // namespace ambfplus
