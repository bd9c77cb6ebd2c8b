#pragma once

#include <array>
#include <cstdint>
#include <future>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/volume/distance_field.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Distances from points to structures of a volume (one label each), from one DistanceField per
/// structure that follows the volume's edits: the drill's critical-distance report and its
/// fixtures read the same fields.
///
/// A field is exact (trilinear between exact voxel-centre values) up to its band; beyond it the
/// answer is the distance to the box around the structure's voxel centres, never less than the
/// band: a lower bound that is exact straight above a flat face and keeps every query O(1).
///
/// Following a cut costs a transform of the band around it (tens of milliseconds for a band of
/// millimetres), too long for a 1 kHz tick. So each field lives on a copy of the structure's
/// neighbourhood (its snapshot) and its successor is made on a thread of its own at normal
/// priority: a copy of the field and snapshot with the cut voxels applied, brought up to date
/// locally (DistanceField::update: only the band around the cut is recomputed), or a build from
/// a new snapshot when the structure grew beyond its neighbourhood or another edit's box reaches
/// out of it. The field in use is replaced kFollowTicks ticks after the edit that started the
/// work (waiting for it if the machine is slower): answers depend on the tick, never on the
/// threads' timing, so scripted runs stay deterministic. Until then the old field answers; a cut
/// only removes voxels, so its distances are then a lower bound, on the safe side for fixtures.
class AMBFPLUS_API StructureDistances {
 public:
  explicit StructureDistances(const VolumeData& data);
  ~StructureDistances();
  StructureDistances(const StructureDistances&) = delete;
  StructureDistances& operator=(const StructureDistances&) = delete;

  /// Ticks after an edit of a structure at which its rebuilt field is taken into use.
  static constexpr std::int64_t kFollowTicks = 50;

  /// The structures that are not a label: every labelled voxel outside the planned region, and
  /// every labelled voxel inside it (the plan's target not yet removed). Labels are 1..65535.
  static constexpr int kOutsidePlan = 0;
  static constexpr int kPlanTarget = -1;

  /// Tracks a structure (a label, kOutsidePlan or kPlanTarget) with a field of at least `band`
  /// metres, built now (a narrower field is rebuilt, a wider one kept).
  void track(int label, double band);
  /// Tracks the structure made of several labels (ids must be non-zero) and returns the key its
  /// distance is asked with (a key below kPlanTarget; the same labels give the same key).
  int track_labels(const std::vector<std::uint16_t>& labels, double band);
  /// The planned region: mask[i + nx (j + ny k)] != 0 for voxels in the plan, which the
  /// structures kOutsidePlan and kPlanTarget are made of; their fields are rebuilt at once if
  /// tracked.
  void set_plan(std::shared_ptr<const std::vector<std::uint8_t>> mask);
  bool tracks(int label) const { return find(label) != nullptr; }

  /// Tells that the edit(s) from revision `before` to the volume's current one removed voxels of
  /// these labels and nothing else: their structures are rebuilt, the others skip the edits.
  /// `before` < 0: every edit since the last tick (a caller told of all of them).
  void removed(std::int64_t before, const std::vector<std::array<int, 3>>& voxels,
               const std::vector<std::uint16_t>& labels);
  /// One tick: notices edits made by others (their boxes are scanned), takes rebuilt fields
  /// that are due, and starts the rebuilds that are waiting. `wait`: a due field not yet built
  /// is waited for (deterministic, scripted stepping); without it (a real-time loop, which must
  /// never block) it is taken at the first tick after it is ready.
  void tick(bool wait = true);
  /// One tick that takes exactly the successors of the structures keyed in `take` (waiting for
  /// them if not yet built) and no other: a replay of the ticks at which a real-time run took
  /// them (taken()), so that it sees every field when the run did. Throws StateError for a key
  /// whose structure has no successor under way (a schedule from another session).
  void tick_taking(const std::vector<int>& take);
  /// The keys (labels, as track_labels gives them) whose successors the last tick took.
  const std::vector<int>& taken() const { return taken_; }

  /// Distance (metres) from p (volume frame) to the nearest centre of a voxel of `label`,
  /// negative inside, infinity when none is left; its gradient when asked (zero beyond the
  /// band). The label must be tracked.
  double distance(int label, const Eigen::Vector3d& p, Eigen::Vector3d* gradient = nullptr) const;
  /// Rebuilt fields taken into use so far (for tests).
  std::int64_t rebuilds() const { return rebuilds_; }
  /// Of the successors started so far, those made by a local update (for tests).
  std::int64_t local_updates() const { return local_updates_; }
  /// Due fields that were not built yet when taken with `wait`, and the seconds (wall clock)
  /// waited for them: how far the machine fell behind kFollowTicks.
  std::int64_t waits() const { return waits_; }
  double wait_seconds() const { return wait_seconds_; }

 private:
  /// A field on a snapshot of the structure's neighbourhood; immutable once built.
  struct Field {
    std::unique_ptr<VolumeData> snapshot;  // membership (1) over `box` of the volume
    std::unique_ptr<DistanceField> field;
    VoxelBox box;            // the snapshot's voxels in the volume
    Eigen::Vector3d offset;  // volume frame minus snapshot frame
    Eigen::Vector3d lo, hi;  // the box around the structure's voxel centres, volume frame
    VoxelBox bounds;         // the structure's voxels in the volume (empty: none)
  };
  struct Entry {
    int label = 0;
    double band = 0;
    std::shared_ptr<const Field> current;
    std::future<std::shared_ptr<const Field>> next;
    std::int64_t due = 0;  // the tick at which `next` is taken
    bool changed = false;  // edited since `next`'s snapshot (or with no rebuild running)
    VoxelBox grown;        // where edits may have added voxels beyond current->bounds
    // The changes since `next`'s snapshot, for a local update: the box (volume voxels, inside
    // current->box) holding every changed voxel; `whole` when only a new build will do.
    VoxelBox cut;
    bool whole = false;
    // The field replaced last, kept to be brought up to date in place next time (no megabytes
    // allocated or freed per update), and where it differs from `current`.
    std::shared_ptr<const Field> spare;
    VoxelBox spare_lag;
    VoxelBox next_patch;  // what `next` applies to its base; empty for a new build
  };
  Entry* find(int label);
  const Entry* find(int label) const;
  /// The structure's voxels over `bounds` grown by the band, copied; a field is built from it
  /// on another thread.
  std::future<std::shared_ptr<const Field>> rebuild(const Entry& e, const VoxelBox& bounds) const;
  std::shared_ptr<const Field> build(int label, double band, const VoxelBox& bounds) const;
  static std::shared_ptr<const Field> finish(std::unique_ptr<VolumeData> snapshot,
                                             std::unique_ptr<DistanceField> field, VoxelBox box,
                                             Eigen::Vector3d offset);
  /// The successor of e.current with the structure's voxels over e.cut as they are now: a copy
  /// brought up to date locally, on another thread.
  std::future<std::shared_ptr<const Field>> follow(Entry& e);
  /// Starts e's successor (a local update or a new build) and clears e's record of changes.
  void start(Entry& e);
  /// Replaces the field in use by its successor (waiting for it if need be).
  void take(Entry& e);
  std::unique_ptr<VolumeData> copy(int label, const VoxelBox& box) const;
  /// Whether voxel (i, j, k), whose label is l, belongs to the structure of `label`.
  bool member(int label, std::uint16_t l, int i, int j, int k) const {
    if (label > 0) return l == label;
    if (l == 0) return false;
    if (label < kPlanTarget) return sets_[static_cast<std::size_t>(kPlanTarget - 1 - label)][l];
    const auto& n = data_.shape();
    const bool planned =
        (*plan_)[static_cast<std::size_t>(i) +
                 static_cast<std::size_t>(n[0]) *
                     (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * k)] != 0;
    return label == kPlanTarget ? planned : !planned;
  }
  void notice_edits();

  const VolumeData& data_;
  std::vector<Entry> entries_;
  std::int64_t tick_ = 0;
  std::int64_t seen_ = -1;  // the volume revision whose edits are accounted for
  std::int64_t rebuilds_ = 0;
  std::int64_t local_updates_ = 0;
  std::int64_t waits_ = 0;
  std::vector<int> taken_;
  double wait_seconds_ = 0.0;
  std::shared_ptr<const std::vector<std::uint8_t>> plan_;
  std::vector<std::vector<bool>> sets_;  // by key kPlanTarget - 1 - n: membership by label id
  std::vector<std::vector<std::uint16_t>> set_labels_;
  // One background thread at normal priority runs the builds, the local updates and the freeing
  // of replaced fields (megabytes: munmap takes milliseconds), in order. A tick only hands it
  // work: it never creates a thread (which maps a stack) nor frees a field itself.
  class Worker;
  std::unique_ptr<Worker> worker_;
};

}  // namespace ambfplus
