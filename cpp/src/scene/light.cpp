#include "ambfplus/scene/light.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

namespace ambfplus {

Light::Light(Model& model, const LightSpec& spec, int id)
    : Object(model, spec.name, id),
      type_(spec.type),
      color_(spec.color),
      intensity_(spec.intensity),
      spot_cutoff_(spec.spot_cutoff),
      spot_exponent_(spec.spot_exponent),
      attenuation_(spec.attenuation),
      shadow_quality_(spec.shadow_quality) {
  spec.validate();
  const double n = spec.direction.norm();
  // Any rotation whose z axis is the direction will do; pick the one nearest the identity.
  const Eigen::Vector3d z = spec.direction / n;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z).toRotationMatrix();
  pose.translation() = spec.position;
  set_pose(pose);
}

void Light::set_shadow_quality(int quality) {
  if (quality < 0 || quality > kMaxShadowQuality) {
    throw ArgumentError("light '" + name() + "': shadow_quality must be 0 (none) to " +
                        std::to_string(kMaxShadowQuality) + ", got " + std::to_string(quality));
  }
  shadow_quality_ = quality;
}

Eigen::Vector3d Light::direction() const { return pose().linear().col(2).normalized(); }

}  // namespace ambfplus
