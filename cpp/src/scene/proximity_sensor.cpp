// ProximitySensor's scene side: checking the spec, placing the rays.

#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

std::vector<SensorRay> parametric_sensor_rays(int resolution, double horizontal_angle,
                                              double vertical_angle, double start_offset) {
  if (resolution < 2) {
    throw ArgumentError("a parametric sensor needs a resolution of at least 2, got " +
                        std::to_string(resolution));
  }
  if (!std::isfinite(horizontal_angle) || !std::isfinite(vertical_angle) ||
      !std::isfinite(start_offset)) {
    throw ArgumentError("a parametric sensor's angles and start offset must be finite");
  }
  std::vector<SensorRay> rays;
  rays.reserve(static_cast<std::size_t>(resolution) * resolution);
  const double step_h = horizontal_angle / (resolution - 1);
  const double step_v = vertical_angle / (resolution - 1);
  for (int i = 0; i < resolution; ++i) {
    const double yaw = -horizontal_angle / 2 + i * step_h;
    for (int j = 0; j < resolution; ++j) {
      const double pitch = -vertical_angle / 2 + j * step_v;
      const Eigen::Vector3d d =
          Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitX());
      rays.push_back({d * start_offset, d});
    }
  }
  return rays;
}

ProximitySensor::ProximitySensor(Model& model, const ProximitySensorSpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string& name = spec.name;
  if (spec_.parent == nullptr) {
    throw ArgumentError("sensor '" + name + "' needs a parent body");
  }
  if (&spec_.parent->world() != &model.world()) {
    throw ArgumentError("sensor '" + name + "': its parent '" + spec_.parent->name() +
                        "' is in another world");
  }
  spec_.validate();
  hits_.resize(spec_.rays.size());
  Object::set_pose(spec_.parent->pose() * checked_pose(spec_.location));
}

void ProximitySensor::set_range(double range) {
  if (!(range > 0) || !std::isfinite(range)) {
    throw ArgumentError("sensor '" + name() + "': range must be > 0 m, got " +
                        std::to_string(range));
  }
  spec_.range = range;
}

bool ProximitySensor::triggered() const {
  for (const SensorHit& h : hits_) {
    if (h.triggered) return true;
  }
  return false;
}

void ProximitySensor::check_ray(int ray) const {
  if (ray < 0 || ray >= static_cast<int>(ray_count())) {
    throw OutOfRange("sensor '" + name() + "' has rays 0.." +
                     std::to_string(static_cast<int>(ray_count()) - 1) + ", not " +
                     std::to_string(ray));
  }
}

Eigen::Vector3d ProximitySensor::ray_start(int ray) const {
  check_ray(ray);
  return parent().pose() * checked_pose(spec_.location) * spec_.rays[ray].offset;
}

Eigen::Vector3d ProximitySensor::ray_end(int ray) const {
  check_ray(ray);
  const SensorRay& r = spec_.rays[ray];
  return parent().pose() * checked_pose(spec_.location) * (r.offset + r.direction * spec_.range);
}

void ProximitySensor::set_pose(const Eigen::Isometry3d& pose) {
  spec_.location = (parent().pose().inverse() * pose).matrix();
  Object::set_pose(pose);
}

}  // namespace ambfplus
