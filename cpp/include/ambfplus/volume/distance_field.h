#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// What a distance field says at a point: the signed distance (metres) and its gradient.
struct AMBFPLUS_API DistanceSample {
  /// Positive outside the structure, negative inside, clamped to [-band, band].
  double distance = 0.0;
  /// d(distance)/d(point), volume frame; zero where the field is clamped on all sides.
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
};

/// The exact Euclidean signed distance from each voxel centre of a volume to a structure (the
/// voxels whose label is one of `labels`), in metres, clamped to a band. Outside the structure a
/// voxel holds the distance from its centre to the nearest structure voxel's centre (the measure
/// the critical-distance report has always used); inside, minus the distance to the nearest
/// centre of a voxel not in the structure. Anisotropic voxels are exact: the transform is the
/// separable lower envelope of parabolas (Felzenszwalb and Huttenlocher) with each axis's
/// spacing.
///
/// Values beyond the band are clamped to it, which is what makes updates exact and local: an
/// edit that changes the structure's voxels in a box B can change only values within the band of
/// B, and those depend only on structure voxels within twice the band of B. update() recomputes
/// that region, so a field brought up to date equals a fresh build. Edits that do not change
/// which voxels belong to the structure (drilling bone) cost a scan of their box.
///
/// The field is stored only over the structure's bounding box grown by the band (elsewhere the
/// distance is the band), so small structures in large volumes stay small.
class AMBFPLUS_API DistanceField {
 public:
  /// Builds the field of `labels` in `data` (ids must be non-zero), clamped to band metres
  /// (> 0). Throws ArgumentError for an empty label list, a zero id or a band that is not a
  /// positive finite number.
  DistanceField(const VolumeData& data, std::vector<std::uint16_t> labels, double band);

  /// A copy of `other` that follows `data` from now on: data must have other's volume's shape
  /// and voxel size and hold what that volume held at other.revision(). The copy reflects data's
  /// current revision; update() then recomputes only around data's later edits (how a field on
  /// a snapshot is brought up to date on another snapshot without a full build). Throws
  /// ArgumentError for another shape or voxel size.
  DistanceField(const DistanceField& other, const VolumeData& data);

  /// Brings the field up to the volume's current revision: recomputes the regions whose
  /// structure voxels changed since, and returns the number of voxels recomputed (0 when no
  /// edit touched the structure).
  std::int64_t update();

  /// Declares that the volume's edits up to `revision` changed none of the structure's voxels,
  /// for a caller that knows what each edit removed (the skill metrics, told a tick's removed
  /// voxels and their labels): the scan of those edits' boxes is skipped. An edit it vouches for
  /// wrongly is not seen until the next full rebuild.
  void skip_to(std::int64_t revision) { revision_ = std::max(revision_, revision); }

  /// The volume revision the field reflects.
  std::int64_t revision() const { return revision_; }
  double band() const { return band_; }
  const VolumeData& volume() const { return data_; }
  const std::vector<std::uint16_t>& labels() const { return labels_; }
  /// Structure voxels the field was last built or updated from.
  std::int64_t structure_voxels() const { return structure_voxels_; }
  /// The structure's voxel bounding box at the last full build (empty without voxels): edits
  /// that only remove voxels keep it, so it then holds the structure with room to spare.
  const VoxelBox& bounds() const { return bounds_; }

  /// The signed distance at voxel (i, j, k)'s centre; throws OutOfRange outside the grid.
  double at(int i, int j, int k) const;
  /// Trilinear interpolation of the voxel-centre values at p (volume frame) and the gradient of
  /// that interpolant. Points beyond the outer voxel centres take the value of the nearest one
  /// inside the grid (the gradient has no component along a clamped axis).
  DistanceSample sample(const Eigen::Vector3d& p) const;
  /// The signed distance of every voxel, i fastest (a copy; for tests and offline analysis).
  std::vector<float> values() const;

 private:
  bool member(int i, int j, int k) const;
  /// Recomputes the stored values in `box` (clipped to the stored region) from the structure.
  std::int64_t recompute(const VoxelBox& box);
  /// The stored region for the structure's current bounding box (empty when it has no voxel).
  VoxelBox region_for(const VoxelBox& bounds) const;
  void rebuild();
  double stored(int i, int j, int k) const;

  const VolumeData& data_;
  std::vector<std::uint16_t> labels_;
  std::vector<bool> is_member_;  // by label id
  double band_;
  std::array<int, 3> reach_;  // voxels per axis that the band spans (rounded up)
  std::int64_t revision_ = 0;
  std::int64_t structure_voxels_ = 0;

  VoxelBox bounds_;                 // the structure's voxels at the last rebuild
  VoxelBox region_;                 // where values_ is stored; elsewhere the value is band
  std::vector<float> values_;       // packed over region_, i fastest
  std::vector<std::uint8_t> mask_;  // structure membership over region_ at revision_
};

}  // namespace ambfplus
