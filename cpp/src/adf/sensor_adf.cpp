// A model file's `sensors` (proximity) and `actuators` (constraint) blocks.

#include <yaml-cpp/yaml.h>

#include <string>

#include "adf/model_blocks.h"
#include "util/strings.h"

namespace ambfplus::adf {

std::optional<SensorPlan> plan_sensor(const Doc& doc, const std::string& model_ns, bool actuator,
                                      const std::string& id, const YAML::Node& n, Context& ctx) {
  const char* what = actuator ? "actuator" : "sensor";
  if (!n["type"]) {
    ctx.diag->warn(doc.path, at(n) + id + ": a " + what + " without 'type' is left out");
    return std::nullopt;
  }
  const std::string type = to_lower(text(doc, n["type"], id, "type"));
  if ((actuator && type != "constraint") || (!actuator && type != "proximity")) {
    ctx.diag->warn(doc.path, at(n["type"]) + id + ": " + what + " type '" +
                                 text(doc, n["type"], id, "type") +
                                 "' is not supported yet; left out");
    return std::nullopt;
  }
  if (actuator) {
    ctx.diag->unknown_keys(doc, id, n,
                           {"name", "namespace", "type", "parent", "location", "max impulse", "tau",
                            "visible", "visible size", "publish frequency", "passive", "plugins"});
  } else {
    ctx.diag->unknown_keys(
        doc, id, n,
        {"name", "namespace", "type", "parent", "location", "range", "array", "parametric", "mesh",
         "direction", "visible", "visible size", "publish frequency", "passive", "plugins"});
  }
  if (!n["parent"]) fail(doc, n, id, std::string("a ") + what + " needs 'parent'");
  SensorPlan p;
  p.id = id;
  p.block = n;
  p.actuator = actuator;
  p.ns = block_ns(doc, ctx, model_ns, id, n);
  p.parent = text(doc, n["parent"], id, "parent");
  p.plugins = read_plugins(doc, n["plugins"], id);
  const std::string name = block_name(doc, id, n);
  const Eigen::Matrix4d location = frame(doc, n["location"], id, "location");
  if (actuator) {
    ConstraintActuatorSpec& a = p.act;
    a.name = name;
    a.location = location;
    set_options(doc, id, n, constraint_actuator_options(), a,
                {"max impulse", "tau", "visible", "visible size"});
    return p;
  }
  ProximitySensorSpec& s = p.sensor;
  s.name = name;
  s.location = location;
  set_options(doc, id, n, proximity_sensor_options(), s, {"range", "visible", "visible size"});
  if (const YAML::Node array = n["array"]) {
    if (!array.IsSequence()) fail(doc, array, id, "'array' must be a list of {offset, direction}");
    // AMBF's {x, y, z} mappings, absent components from the defaults.
    for (const YAML::Node& ray : array) {
      SensorRay r;
      r.offset = xyz(doc, ray["offset"], id, "array.offset", r.offset);
      r.direction = xyz(doc, ray["direction"], id, "array.direction", r.direction);
      s.rays.push_back(r);
    }
  } else if (n["parametric"]) {
    set_options(doc, id, n, proximity_sensor_options(), s, {"parametric"});
  } else if (n["mesh"]) {
    ctx.diag->warn(
        doc.path, at(n["mesh"]) + id + ": sensor rays from a mesh are not supported yet; left out");
    return std::nullopt;
  } else if (const YAML::Node direction = n["direction"]) {
    // AMBF's older form: one ray from the sensor's location along `direction`, `range` long.
    SensorRay r;
    r.offset = Eigen::Vector3d::Zero();
    r.direction = xyz(doc, direction, id, "direction", Eigen::Vector3d::Zero());
    if (!(r.direction.norm() > 1e-12)) fail(doc, direction, id, "'direction' must not be zero");
    r.direction.normalize();
    s.rays.push_back(r);
  } else {
    fail(doc, n, id,
         "a proximity sensor needs 'array' or 'parametric' rays, or one ray's 'direction'");
  }
  return p;
}

}  // namespace ambfplus::adf
