#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Distances from a point to labelled structures (the critical ones of a volume), exact to the
/// voxel centre and current with every removal. Each label's boundary voxels sit in a k-d tree
/// whose nodes know their bounding boxes, so a query, near or far, opens only the few nodes that
/// can hold something nearer than the best found so far. Removed voxels are
/// skipped (their label no longer matches); neighbours a removal exposes join a short list that
/// is folded into the tree once it grows.
class CriticalDistances {
 public:
  CriticalDistances(const VolumeData& data, const std::vector<std::uint16_t>& labels);

  /// Distance (metres) from p (volume frame) to the nearest centre of a voxel with this label,
  /// or infinity when none is left.
  double distance(const Eigen::Vector3d& p, std::uint16_t label);
  /// Tells that voxel v (which had `label`) was removed: its neighbours of that label may now
  /// be on the structure's boundary.
  void removed(const std::array<int, 3>& v, std::uint16_t label);
  const std::vector<std::uint16_t>& labels() const { return labels_; }

 private:
  struct Point {
    Eigen::Vector3d p;
    std::array<int, 3> voxel;
  };
  struct Tree {
    std::vector<Point> points;  // in k-d order: each node splits its range at the middle
    std::vector<std::uint8_t> axis;
    std::vector<Eigen::Vector3d> box_lo, box_hi;  // bounds of each node's range
    std::vector<Point> added;                     // exposed since the last build
  };
  void build(Tree& tree);
  void build(Tree& tree, std::size_t lo, std::size_t hi);
  void search(const Tree& tree, std::size_t lo, std::size_t hi, const Eigen::Vector3d& p,
              std::uint16_t label, double& best) const;
  bool alive(const Point& q, std::uint16_t label) const {
    return data_.label(q.voxel[0], q.voxel[1], q.voxel[2]) == label;
  }

  const VolumeData& data_;
  std::vector<std::uint16_t> labels_;
  std::map<std::uint16_t, Tree> trees_;
};

}  // namespace ambfplus
