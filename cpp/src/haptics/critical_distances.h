#pragma once

#include <array>
#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Distances from a point to labelled structures (the critical ones of a volume), exact to the
/// voxel centre and current with every removal. Each label's boundary voxels sit in a k-d tree
/// whose nodes know their bounding boxes, so a query, near or far, opens only the few nodes that
/// can hold something nearer than the best found so far. Removed voxels are skipped (their label
/// no longer matches); neighbours a removal exposes join a short list that queries scan, and
/// which is folded into a new tree once it grows. That rebuild takes hundreds of milliseconds
/// for a large structure, so it runs on a thread of its own at normal priority and the new tree
/// replaces the old one at the first query after it is done: a haptic step never waits for it.
/// Answers do not depend on when that happens (both trees with the list hold the same voxels).
class CriticalDistances {
 public:
  CriticalDistances(const VolumeData& data, const std::vector<std::uint16_t>& labels);
  ~CriticalDistances();
  CriticalDistances(const CriticalDistances&) = delete;
  CriticalDistances& operator=(const CriticalDistances&) = delete;

  /// Distance (metres) from p (volume frame) to the nearest centre of a voxel with this label,
  /// or infinity when none is left.
  double distance(const Eigen::Vector3d& p, std::uint16_t label);
  /// Tells that voxel v (which had `label`) was removed: its neighbours of that label may now
  /// be on the structure's boundary.
  void removed(const std::array<int, 3>& v, std::uint16_t label);
  const std::vector<std::uint16_t>& labels() const { return labels_; }
  /// Exposed voxels kept in the list before a rebuild starts.
  static constexpr std::size_t kRebuildAfter = 4096;
  /// Rebuilt trees taken into use so far (for tests).
  std::int64_t rebuilds() const { return rebuilds_; }

 private:
  struct Point {
    Eigen::Vector3d p;
    std::array<int, 3> voxel;
  };
  /// Immutable once built: queries read it while a rebuild makes the next one.
  struct Tree {
    std::vector<Point> points;  // in k-d order: each node splits its range at the middle
    std::vector<std::uint8_t> axis;
    std::vector<Eigen::Vector3d> box_lo, box_hi;  // bounds of each node's range
  };
  struct Structure {
    std::shared_ptr<const Tree> tree;
    std::vector<Point> added;  // exposed since tree was built
    std::future<std::shared_ptr<const Tree>> rebuilding;
    std::size_t folding = 0;     // added[0, folding) are in the tree being rebuilt
    std::future<void> retiring;  // frees a replaced tree (tens of MB: munmap takes milliseconds)
  };
  static std::shared_ptr<const Tree> build(std::vector<Point> points);
  static void build(Tree& tree, std::size_t lo, std::size_t hi);
  /// Takes a finished rebuild's tree.
  void collect(Structure& s);
  void search(const Tree& tree, std::size_t lo, std::size_t hi, const Eigen::Vector3d& p,
              std::uint16_t label, double& best) const;
  bool alive(const Point& q, std::uint16_t label) const {
    return data_.label(q.voxel[0], q.voxel[1], q.voxel[2]) == label;
  }

  const VolumeData& data_;
  std::vector<std::uint16_t> labels_;
  std::map<std::uint16_t, Structure> structures_;
  std::int64_t rebuilds_ = 0;
};

}  // namespace ambfplus
