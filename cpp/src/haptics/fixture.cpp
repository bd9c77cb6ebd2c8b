// FixtureSpec: its checks and its keys.

#include "ambfplus/haptics/fixture.h"

#include <cmath>
#include <sstream>

#include "ambfplus/errors.h"

namespace ambfplus {

void FixtureSpec::validate(const std::string& who) const {
  std::ostringstream bad;
  if (structure.empty())
    bad << "a fixture needs a structure (a label name or id)";
  else if (!(start > 0 && std::isfinite(start)))
    bad << "start must be > 0 m, got " << start;
  else if (!(max_force >= 0 && std::isfinite(max_force))) {
    bad << "max_force must be >= 0 N, got " << max_force;
  } else if (!(stop >= 0 && std::isfinite(stop))) {
    bad << "stop must be >= 0 m (or None), got " << stop;
  }
  if (!bad.str().empty()) {
    throw ArgumentError(who + "fixture '" + structure + "': " + bad.str());
  }
}

const OptionTable<FixtureSpec>& fixture_options() {
  using S = FixtureSpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "fixture", {
                     O{"structure", "str | int", "label name or id",
                       [](S& s, V v, K k) {
                         s.structure = v.type() == OptionValue::Type::kInteger
                                           ? std::to_string(v.integer(k))
                                           : v.text(k);
                       }},
                     O{"start", "float", "m from the burr's surface: the force starts",
                       [](S& s, V v, K k) { s.start = v.number(k); }},
                     O{"max_force", "float", "N at the structure",
                       [](S& s, V v, K k) { s.max_force = v.number(k); }},
                     O{"stop", "float | None", "m: no cutting nearer, the burr is held there",
                       [](S& s, V v, K k) { s.stop = v.is_none() ? 0.0 : v.number(k); }},
                     O{"enabled", "bool", "", [](S& s, V v, K k) { s.enabled = v.boolean(k); }},
                 });
  return table;
}

}  // namespace ambfplus
