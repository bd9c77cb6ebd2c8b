// ConstraintActuatorSpec: its checks and its keyword options.

#include <algorithm>
#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/rigid_body.h"
#include "scene/shared_options.h"
#include "util/strings.h"

namespace ambfplus {

ActuatorHold parse_actuator_hold(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "fixed") return ActuatorHold::kFixed;
  if (n == "point") return ActuatorHold::kPoint;
  throw ArgumentError("hold must be 'fixed' or 'point', got '" + name + "'");
}

const char* actuator_hold_name(ActuatorHold hold) {
  return hold == ActuatorHold::kFixed ? "fixed" : "point";
}

void ConstraintActuatorSpec::validate() const {
  const std::string who = "actuator '" + name + "'";
  checked_pose(location, who + " location");
  if (!(max_impulse > 0) || !std::isfinite(max_impulse)) {
    throw ArgumentError(who + ": max impulse must be > 0 N s, got " + std::to_string(max_impulse));
  }
  if (!(tau > 0 && tau <= 1)) {
    throw ArgumentError(who + ": tau must be in (0, 1], got " + std::to_string(tau));
  }
  if (!(visible_size >= 0) || !std::isfinite(visible_size)) {
    throw ArgumentError(who + ": visible size must be >= 0");
  }
}

const OptionTable<ConstraintActuatorSpec>& constraint_actuator_options() {
  using S = ConstraintActuatorSpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "add_actuator()",
      joined<O>(
          {
              O{"hold", "ActuatorHold | str", "fixed (the body keeps its pose) or point",
                [](S& s, V v, K k) { s.hold = parse_actuator_hold(v.text(k)); }},
              O{"max_impulse", "float", "N s per step (point hold)",
                [](S& s, V v, K k) { s.max_impulse = v.number(k); }},
              O{"tau", "float", "share of the point error corrected per step (point hold)",
                [](S& s, V v, K k) { s.tau = v.number(k); }},
          },
          attachment_options<S>("an actuator")),
      [](S& s, const std::vector<std::string>& given) {
        const auto has = [&](const char* k) {
          return std::find(given.begin(), given.end(), k) != given.end();
        };
        if (has("location") && has("pose")) {
          throw ArgumentError("actuator '" + s.name +
                              "': give location (in the parent's frame) or pose (world), not "
                              "both");
        }
      });
  return table;
}

}  // namespace ambfplus
