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

/// The kind a user names ("body", "joint", "camera", ... as object_kind_name gives them).
/// Throws ArgumentError listing the names for one that is none of them.
AMBFPLUS_API ObjectKind parse_object_kind(std::string_view name);

/// The objects a name refers to, by AMBF's rules, optionally of one kind:
/// 1. an object with exactly this name (of the kind) is the answer alone;
/// 2. else World::lookup: names, qualified names ("/ambf/env/l1"), identifiers ("BODY l1") and
///    namespace + identifier equal to the name, or failing those, containing it;
/// 3. when several match and no kind was asked for, joints are left out if that leaves one
///    (AMBF's clients find bodies, cameras and lights by name; joints only when asked for).
/// One result is a match; none or several are for the caller to report (resolve_name does).
AMBFPLUS_API std::vector<Object*> name_candidates(const World& world, const std::string& name,
                                                  std::optional<ObjectKind> kind = std::nullopt);

/// The one object a name refers to (name_candidates). Throws NotFound saying that nothing
/// matches, or that the name is ambiguous with the first matches' qualified names.
AMBFPLUS_API Object& resolve_name(const World& world, const std::string& name,
                                  std::optional<ObjectKind> kind = std::nullopt);

}  // namespace ambfplus
