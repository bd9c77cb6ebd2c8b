#include "ambfplus/scene/light.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "util/strings.h"

namespace ambfplus {

LightSpec::Type parse_light_type(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "directional") return LightSpec::Type::kDirectional;
  if (n == "point") return LightSpec::Type::kPoint;
  if (n == "spot") return LightSpec::Type::kSpot;
  throw ArgumentError("unknown light type '" + name + "': expected directional, point or spot");
}

const char* light_type_name(LightSpec::Type type) {
  switch (type) {
    case LightSpec::Type::kDirectional:
      return "directional";
    case LightSpec::Type::kPoint:
      return "point";
    case LightSpec::Type::kSpot:
      return "spot";
  }
  return "?";
}

Light::Light(Model& model, const LightSpec& spec, int id)
    : Object(model, spec.name, id),
      type_(spec.type),
      color_(spec.color),
      intensity_(spec.intensity),
      spot_cutoff_(spec.spot_cutoff),
      spot_exponent_(spec.spot_exponent),
      attenuation_(spec.attenuation) {
  const double n = spec.direction.norm();
  if (!(n > 0.0) || !spec.direction.allFinite() || !spec.position.allFinite()) {
    throw ArgumentError("light '" + spec.name +
                        "': needs a finite position and a non-zero direction");
  }
  // Any rotation whose z axis is the direction will do; pick the one nearest the identity.
  const Eigen::Vector3d z = spec.direction / n;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z).toRotationMatrix();
  pose.translation() = spec.position;
  set_pose(pose);
}

Eigen::Vector3d Light::direction() const { return pose().linear().col(2).normalized(); }

}  // namespace ambfplus
