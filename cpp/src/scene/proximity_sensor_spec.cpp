// ProximitySensorSpec: its checks and its keyword options.

#include <algorithm>
#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "scene/shared_options.h"

namespace ambfplus {
namespace {

using S = ProximitySensorSpec;
using V = const OptionValue&;
using K = const std::string&;
using O = OptionTable<S>::Option;

bool given(const std::vector<std::string>& keys, const char* key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

// The one ray that offset and direction describe (made on first use).
SensorRay& single_ray(S& s) {
  if (s.rays.empty()) s.rays.emplace_back();
  return s.rays.front();
}

// A ray from {offset, direction} or (offset, direction).
SensorRay parse_ray(V v, K k) {
  SensorRay r;
  if (v.is_map()) {
    for (const OptionEntry& e : v.map(k)) {
      if (e.key == "offset") {
        r.offset = e.value.vector3(k + ".offset");
      } else if (e.key == "direction") {
        r.direction = e.value.vector3(k + ".direction");
      } else {
        throw ArgumentTypeError("a ray takes offset and direction, got '" + e.key + "'");
      }
    }
    return r;
  }
  const std::vector<OptionValue>& pair = v.list(k);
  if (pair.size() != 2)
    throw ArgumentTypeError("a ray is {offset, direction} or (offset, direction)");
  r.offset = pair[0].vector3(k + " offset");
  r.direction = pair[1].vector3(k + " direction");
  return r;
}

// Cross-key rules: one way of giving rays, one way of placing the sensor.
void finish(S& s, const std::vector<std::string>& keys) {
  const bool fan = given(keys, "rays") || given(keys, "parametric");
  if (fan && (given(keys, "offset") || given(keys, "direction"))) {
    throw ArgumentError("sensor '" + s.name +
                        "': give rays (or parametric), or one ray by offset and direction, not "
                        "both");
  }
  if (given(keys, "location") && given(keys, "pose")) {
    throw ArgumentError("sensor '" + s.name +
                        "': give location (in the parent's frame) or pose (world), not both");
  }
  if (s.rays.empty() && !fan) s.rays.emplace_back();
}

}  // namespace

std::vector<SensorRay> parametric_sensor_rays(const OptionMap& p) {
  auto number = [&](const char* key, double fallback) {
    const OptionValue* v = find_option(p, key);
    return v ? v->number(key) : fallback;
  };
  for (const OptionEntry& e : p) {
    const std::string k = option_key(e.key);
    if (k != "resolution" && k != "horizontal_angle" && k != "vertical_angle" &&
        k != "start_offset") {
      throw ArgumentTypeError(
          "parametric takes resolution, horizontal angle, vertical angle and start offset, got '" +
          e.key + "'");
    }
  }
  const OptionValue* resolution = find_option(p, "resolution");
  return parametric_sensor_rays(resolution ? resolution->integer("resolution") : 2,
                                number("horizontal angle", 0.0), number("vertical angle", 0.0),
                                number("start offset", 0.0));
}

void ProximitySensorSpec::validate() const {
  const std::string who = "sensor '" + name + "'";
  checked_pose(location, who + " location");
  if (!(range > 0) || !std::isfinite(range)) {
    throw ArgumentError(who + ": range must be > 0 m, got " + std::to_string(range));
  }
  if (rays.empty()) throw ArgumentError(who + " needs at least one ray");
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const SensorRay& r = rays[i];
    if (!r.offset.allFinite() || !r.direction.allFinite() || r.direction.norm() == 0) {
      throw ArgumentError(who + ": ray " + std::to_string(i) +
                          " needs a finite offset and a finite, non-zero direction");
    }
  }
  if (!(visible_size >= 0) || !std::isfinite(visible_size)) {
    throw ArgumentError(who + ": visible size must be >= 0");
  }
}

const OptionTable<ProximitySensorSpec>& proximity_sensor_options() {
  static const OptionTable<S> table(
      "add_sensor()",
      joined<O>(
          {
              O{"range", "float", "m each ray reaches (per unit of its direction)",
                [](S& s, V v, K k) { s.range = v.number(k); }},
              O{"offset", "tuple[float, float, float]", "the one ray's start, sensor frame",
                [](S& s, V v, K k) { single_ray(s).offset = v.vector3(k); }},
              O{"direction", "tuple[float, float, float]", "the one ray's direction, sensor frame",
                [](S& s, V v, K k) { single_ray(s).direction = v.vector3(k); }},
              O{"rays",
                "list[Any]",
                "[{offset, direction}] or [(offset, direction)]",
                [](S& s, V v, K k) {
                  for (const OptionValue& r : v.list(k)) s.rays.push_back(parse_ray(r, k));
                },
                {"array"}},
              O{"parametric", "dict[str, float]",
                "{resolution, horizontal angle, vertical angle, start offset}",
                [](S& s, V v, K k) {
                  const auto fan = parametric_sensor_rays(v.map(k));
                  s.rays.insert(s.rays.end(), fan.begin(), fan.end());
                }},
          },
          attachment_options<S>("a sensor")),
      finish);
  return table;
}

}  // namespace ambfplus
