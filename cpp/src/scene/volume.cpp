#include "ambfplus/scene/volume.h"

#include "ambfplus/errors.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"

#include <stdexcept>

namespace ambfplus {

Volume::Volume(Model& model, const VolumeSpec& spec, int id)
    : Object(model, spec.name, id),
      data_(spec.data),
      iso_(spec.iso),
      quality_(spec.quality),
      optical_density_(spec.optical_density),
      specular_(spec.specular),
      shininess_(spec.shininess) {
  spec.validate();
  set_pose(checked_pose(spec.pose));
  if (data_) data_->set_guard(&model.world().state_mutex());
}

Volume::~Volume() {
  // The data may outlive the world: it no longer guards edits with this world's lock.
  if (data_ && data_->guard() == &world().state_mutex()) data_->set_guard(nullptr);
}

void Volume::set_iso(double iso) {
  if (!(iso > 0.0 && iso < 1.0)) {
    throw ArgumentError("volume '" + name() + "': iso must be in (0, 1), got " +
                        std::to_string(iso));
  }
  iso_ = iso;
}

Eigen::Matrix4d Volume::world_from_voxel() const {
  const Eigen::Vector3d s = data_->voxel_size();
  Eigen::Matrix4d volume_from_voxel = Eigen::Matrix4d::Identity();
  volume_from_voxel.topLeftCorner<3, 3>() = s.asDiagonal();
  volume_from_voxel.topRightCorner<3, 1>() = s / 2 - data_->dimensions() / 2;
  return pose().matrix() * volume_from_voxel;
}

Eigen::Vector3d Volume::world_to_voxel(const Eigen::Vector3d& p) const {
  return data_->to_voxel_units(pose().inverse() * p) - Eigen::Vector3d::Constant(0.5);
}

Eigen::Vector3d Volume::voxel_to_world(const Eigen::Vector3d& ijk) const {
  return pose() * data_->from_voxel_units(ijk + Eigen::Vector3d::Constant(0.5));
}

std::int64_t Volume::remove_sphere(const Eigen::Vector3d& world_center, double radius,
                                   bool only_removable) {
  return data_->remove_sphere(pose().inverse() * world_center, radius, only_removable);
}

VolumeHit Volume::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                          double max_distance) {
  const Eigen::Isometry3d inv = pose().inverse();
  VolumeHit hit = data_->raycast(inv * origin, inv.linear() * direction, iso_, max_distance);
  if (hit.hit) {
    hit.position = pose() * hit.position;
    hit.normal = pose().linear() * hit.normal;
  }
  return hit;
}

}  // namespace ambfplus
