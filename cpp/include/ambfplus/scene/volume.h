#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Everything needed to place a volume in a world.
struct AMBFPLUS_API VolumeSpec {
  std::string name;
  std::shared_ptr<VolumeData> data;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  ///< world from volume frame
  double iso = 0.5;              ///< iso-surface of the smoothed occupancy, 0..1 (AMBF's key)
  double quality = 0.5;          ///< AMBF's key, kept for files; steps are always half a voxel
  double optical_density = 1.0;  ///< AMBF's key, kept for files
  float specular = 0.15f;
  float shininess = 24.0f;

  /// Throws ArgumentError naming the volume and the value unless every value can be used (data
  /// given, a rigid pose, iso in (0, 1), the rest finite and >= 0).
  void validate() const;
};

/// add_volume's keyword options: pose, iso, quality, optical_density, specular, shininess.
AMBFPLUS_API const OptionTable<VolumeSpec>& volume_options();

/// A segmented volume placed in a world and rendered by ray casting its iso-surface. Several
/// volumes may share one VolumeData.
class AMBFPLUS_API Volume : public Object {
 public:
  ~Volume() override;
  ObjectKind kind() const override { return ObjectKind::kVolume; }
  const std::shared_ptr<VolumeData>& data() const { return data_; }

  double iso() const { return iso_; }
  /// Throws ArgumentError outside (0, 1).
  void set_iso(double iso);
  double quality() const { return quality_; }
  double optical_density() const { return optical_density_; }
  float specular() const { return specular_; }
  float shininess() const { return shininess_; }
  /// Rays skip empty bricks (default); off, they march every half voxel (the naive baseline).
  bool empty_space_skipping() const { return skipping_; }
  void set_empty_space_skipping(bool on) { skipping_ = on; }

  /// World from voxel indices: voxel (i, j, k)'s centre is this matrix times (i, j, k, 1).
  Eigen::Matrix4d world_from_voxel() const;
  /// Fractional voxel indices of a world point (voxel centres are at integers).
  Eigen::Vector3d world_to_voxel(const Eigen::Vector3d& p) const;
  /// World point of fractional voxel indices.
  Eigen::Vector3d voxel_to_world(const Eigen::Vector3d& ijk) const;

  /// remove_sphere with a world-frame centre; returns how many voxels were cleared.
  std::int64_t remove_sphere(const Eigen::Vector3d& world_center, double radius,
                             bool only_removable = true);
  /// First hit of a world-frame ray with the iso-surface; position and normal in the world frame.
  VolumeHit raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                    double max_distance = 1e9);

 private:
  friend class Model;
  Volume(Model& model, const VolumeSpec& spec, int id);

  std::shared_ptr<VolumeData> data_;
  double iso_;
  double quality_;
  double optical_density_;
  float specular_;
  float shininess_;
  bool skipping_ = true;
};

}  // namespace ambfplus
