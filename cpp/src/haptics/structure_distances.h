#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/volume/distance_field.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Distances from points to structures of a volume (one label each), from one DistanceField per
/// structure that follows the volume's edits: the drill's critical-distance report and its
/// fixtures read the same fields.
///
/// A field is exact (trilinear between exact voxel-centre values) up to its band; beyond it the
/// answer is the distance to the box around the structure's voxel centres, never less than the
/// band: a lower bound that is exact straight above a flat face and that keeps every query O(1)
/// however far away the burr is. A full field over a large volume would make each edit of the
/// structure cost a whole transform.
class StructureDistances {
 public:
  explicit StructureDistances(const VolumeData& data) : data_(data) {}

  /// Tracks a structure with a field of at least `band` metres (a narrower field is rebuilt,
  /// a wider one kept).
  void track(std::uint16_t label, double band);
  bool tracks(std::uint16_t label) const { return find(label) != nullptr; }

  /// Tells that the edit(s) from revision `before` to the volume's current one removed voxels of
  /// these labels and nothing else: fields of other structures skip those edits' boxes.
  void removed(std::int64_t before, const std::vector<std::uint16_t>& labels);
  /// Brings every field up to the volume's revision (only what changed is recomputed).
  void sync();

  /// Distance (metres) from p (volume frame) to the nearest centre of a voxel of `label`,
  /// negative inside, infinity when none is left; its gradient when asked (zero beyond the
  /// band). The label must be tracked.
  double distance(std::uint16_t label, const Eigen::Vector3d& p,
                  Eigen::Vector3d* gradient = nullptr) const;
  /// The band of a tracked label's field.
  double band(std::uint16_t label) const;

 private:
  struct Entry {
    std::uint16_t label;
    std::unique_ptr<DistanceField> field;
    Eigen::Vector3d lo, hi;  // the box around the structure's voxel centres at the last sync
  };
  Entry* find(std::uint16_t label);
  const Entry* find(std::uint16_t label) const;
  void refresh_box(Entry& e) const;

  const VolumeData& data_;
  std::vector<Entry> entries_;
};

}  // namespace ambfplus
