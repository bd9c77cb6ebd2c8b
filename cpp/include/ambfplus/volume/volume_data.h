#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/scene/state_mutex.h"
#include "ambfplus/volume/label_table.h"

namespace ambfplus {

/// A half-open box of voxels [lo, hi) along i, j, k.
struct AMBFPLUS_API VoxelBox {
  std::array<int, 3> lo{0, 0, 0};
  std::array<int, 3> hi{0, 0, 0};

  bool empty() const;
  std::int64_t count() const;
  /// The smallest box holding both (an empty box is ignored).
  VoxelBox united(const VoxelBox& other) const;
  /// This box cut to [0, shape).
  VoxelBox clipped(const std::array<int, 3>& shape) const;
  /// This box grown by margin voxels on every side.
  VoxelBox grown(int margin) const;
  bool operator==(const VoxelBox& o) const { return lo == o.lo && hi == o.hi; }
};

/// Element type of a label grid.
enum class LabelType { kUInt8, kUInt16 };
/// Element type of an intensity (CT) grid.
enum class IntensityType { kNone, kInt16, kFloat32 };

/// One change to a volume's labels, in order of revision.
struct AMBFPLUS_API VolumeEdit {
  std::int64_t revision = 0;
  std::string kind;  ///< "remove_sphere", "set_region", "mark_dirty" or "reset"
  VoxelBox box;      ///< voxels that may have changed
  /// Voxels whose label changed, or -1 when unknown (an edit made through the NumPy view).
  std::int64_t changed = -1;
  /// remove_sphere: the removed voxels (i, j, k) and the labels they had.
  std::vector<std::array<int, 3>> voxels;
  std::vector<std::uint16_t> old_labels;
};

/// Where a ray meets a volume's iso-surface (volume frame, metres).
struct AMBFPLUS_API VolumeHit {
  bool hit = false;
  double t = 0.0;  ///< distance along the (unit) ray direction
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< outward, unit
  std::uint16_t label = 0;
  std::int64_t voxel = -1;  ///< linear index of the voxel whose label this is
};

/// Throws ArgumentError unless sizes are three positive finite metres (a volume's dimensions or
/// voxel size); the message begins with what ("VolumeData: dimensions") and quotes the values.
AMBFPLUS_API void check_volume_sizes(const Eigen::Vector3d& sizes, const std::string& what);

/// A segmented volume: a label grid with its table, an optional intensity grid, its physical size,
/// an edit history and the derived fields rendering and haptics read.
///
/// Grid and frame conventions (AMBF's): voxel (i, j, k) is stored at i + nx * (j + ny * k), i
/// fastest. The volume frame is centred on the grid: voxel (i, j, k) spans
/// [-D/2 + (i, j, k) * s, -D/2 + (i + 1, j + 1, k + 1) * s) with D the dimensions (metres, full
/// extents) and s = D / n the voxel size; x runs along i, y along j, z along k.
/// In "voxel units" u = (p + D/2) / s a voxel covers [i, i + 1) with its centre at i + 0.5.
class AMBFPLUS_API VolumeData {
 public:
  /// A grid of zeros. Throws ArgumentError for a non-positive shape or dimension, or a
  /// table whose ids do not fit the label type.
  VolumeData(const std::array<int, 3>& shape, const Eigen::Vector3d& dimensions, LabelType type,
             LabelTable table);
  VolumeData(const VolumeData&) = delete;
  VolumeData& operator=(const VolumeData&) = delete;

  const std::array<int, 3>& shape() const { return shape_; }
  std::int64_t voxel_count() const;
  const Eigen::Vector3d& dimensions() const { return dimensions_; }
  /// Resizes the physical box (metres, full extents); throws ArgumentError if not > 0.
  void set_dimensions(const Eigen::Vector3d& dimensions);
  Eigen::Vector3d voxel_size() const;
  LabelType label_type() const { return label_type_; }
  const LabelTable& label_table() const { return table_; }
  /// Replaces the table; throws ArgumentError if an id does not fit the label type.
  void set_label_table(LabelTable table);
  /// Names the labels from another table: each label becomes the id of named's label with the
  /// nearest colour (the voxels are relabelled), the table becomes named, and that is what
  /// reset() restores (how the original system's labels.csv names a volume's colours).
  void name_labels_from(const LabelTable& named);
  /// Marks critical structures, unless some label is critical already: the labels whose names
  /// speak of nerves, vessels, the sinus and dura, the labyrinth or the IAC (facial, chorda,
  /// nerve, ica, carotid, sinus, dura, labyrinth, cochlea, iac), else every label but the
  /// commonest (bone).
  void mark_critical_structures();

  /// The label grid (1 or 2 bytes per voxel, by label_type()). Writes through it are not seen by
  /// renderers until mark_dirty() names the changed box.
  void* label_data() { return labels_.data(); }
  const void* label_data() const { return labels_.data(); }
  std::uint16_t label(int i, int j, int k) const {
    const std::size_t n = linear_index(i, j, k);
    return label_type_ == LabelType::kUInt8
               ? labels_[n]
               : reinterpret_cast<const std::uint16_t*>(labels_.data())[n];
  }
  std::size_t linear_index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(shape_[0]) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(shape_[1]) * k);
  }

  IntensityType intensity_type() const { return intensity_type_; }
  /// The intensity grid. Writes through it are not seen by renderers until
  /// mark_intensity_changed().
  void* intensity_data() { return intensity_.empty() ? nullptr : intensity_.data(); }
  /// Allocates a zeroed intensity grid of this type (kNone removes it).
  void set_intensity_type(IntensityType type);
  /// Declares that the intensity grid was changed directly (through intensity_data() or the
  /// NumPy view): renderers read it again.
  void mark_intensity_changed();
  /// Counts set_intensity_type() and mark_intensity_changed() calls.
  std::int64_t intensity_revision() const { return intensity_revision_; }

  /// Centre of voxel (i, j, k) in the volume frame; throws OutOfRange outside the grid.
  Eigen::Vector3d voxel_center(int i, int j, int k) const;
  /// Volume-frame point to continuous voxel units.
  Eigen::Vector3d to_voxel_units(const Eigen::Vector3d& p) const;
  /// Continuous voxel units to a volume-frame point.
  Eigen::Vector3d from_voxel_units(const Eigen::Vector3d& u) const;

  /// Where the grid sat in its source's patient space (e.g. an NRRD's LPS frame), metres:
  /// patient-from-volume-frame, identity when unknown.
  const Eigen::Matrix4d& patient_from_volume() const { return patient_from_volume_; }
  void set_patient_from_volume(const Eigen::Matrix4d& m) { patient_from_volume_ = m; }
  /// The file the grid came from ("" if built in memory).
  const std::string& source() const { return source_; }
  void set_source(const std::string& s) { source_ = s; }

  /// Voxels per label id (index = id), over the whole grid.
  std::vector<std::int64_t> label_counts() const;

  // --- Editing: every edit bumps revision() and records its box for renderers and the log.

  /// Clears the voxels whose centres lie within radius of center (volume frame; both finite, else
  /// ArgumentError); with only_removable, voxels whose label is not removable stay. Returns how
  /// many were cleared.
  std::int64_t remove_sphere(const Eigen::Vector3d& center, double radius,
                             bool only_removable = true);
  /// Clears the given voxels (one edit of `kind`, logging the voxels that were solid and their
  /// labels). Returns the labels they had, 0 for those already empty.
  std::vector<std::uint16_t> remove_voxels(const std::vector<std::array<int, 3>>& voxels,
                                           const std::string& kind = "drill");
  /// Sets every voxel of the box to label (0 clears). Returns how many changed. Throws
  /// ArgumentError for an inverted box (lo > hi) and OutOfRange for one reaching outside the grid.
  std::int64_t set_region(const VoxelBox& box, std::uint16_t label);
  /// Declares that the labels in box were changed directly (through the NumPy view). Throws as
  /// set_region does for an inverted box or one outside the grid.
  void mark_dirty(const VoxelBox& box);
  /// Restores the labels the volume had when it was loaded or last committed.
  void reset();
  /// Makes the current labels the state reset() returns to.
  void commit();
  /// The state lock of the world whose volume shows this data (set by Volume; nullptr while
  /// none does): the edits take it, so that an edit from another thread never runs while the
  /// world steps or renders.
  StateMutex* guard() const { return guard_.load(); }
  void set_guard(StateMutex* mutex) { guard_.store(mutex); }
  /// The guard's lock (not owning one while no world shows the data); the edits above take it.
  std::unique_lock<StateMutex> guard_lock() const {
    StateMutex* mutex = guard_.load();
    return mutex != nullptr ? std::unique_lock<StateMutex>(*mutex) : std::unique_lock<StateMutex>();
  }

  /// Increases with every edit.
  std::int64_t revision() const { return revision_; }
  /// The union of the boxes edited after `since`: returns false when nothing changed. Where the
  /// history no longer reaches back that far, the edits no longer listed count as the union of
  /// every box dropped from it.
  bool dirty_since(std::int64_t since, VoxelBox* box) const;
  /// The boxes edited after `since`, oldest first, a box merged into the one before it where
  /// that costs few extra voxels, and all merged into their union beyond max_boxes: false when
  /// nothing changed; where the history no longer reaches back that far, the union of every box
  /// dropped from it stands for the edits no longer listed. Far-apart edits stay apart, so a
  /// consumer copies what changed, not the box around it.
  bool dirty_boxes_since(std::int64_t since, std::vector<VoxelBox>* boxes,
                         std::size_t max_boxes = 64) const;
  /// Edits kept for edit_log(): the newest kEditLogEdits, holding at most kEditLogVoxels removed
  /// voxels in all; older ones are dropped (and counted) unless taken first.
  static constexpr std::size_t kEditLogEdits = 4096;
  static constexpr std::size_t kEditLogVoxels = 262144;
  const std::deque<VolumeEdit>& edit_log() const { return edit_log_; }
  /// Hands over the edit log and starts a new one.
  std::deque<VolumeEdit> take_edit_log();
  /// Edits dropped from the log because it was full, since the volume was made.
  std::int64_t edit_log_dropped() const { return edit_log_dropped_; }

  // --- Derived fields: computed in full on first access, then brought up to date when read
  // (the boxes edited since, only), so an edit (a haptic tick's removal) costs nothing for them.
  // Renderers compute their own from a copy of the edited labels, off the world's lock
  // (smooth_occupancy and brick_maxima below).

  /// Occupancy (label != 0) blurred by a separable binomial kernel [1 4 6 4 1] / 16, 0..255:
  /// trilinear interpolation of it gives a smooth iso-surface at 0.5 that sits on flat voxel
  /// boundaries, with normals free of voxel steps.
  const std::vector<std::uint8_t>& smoothed_occupancy();
  /// How far (voxels) a label change reaches into the smoothed occupancy.
  static constexpr int kSmoothRadius = 2;
  /// Bricks of kBrickSize^3 voxels: for each, the largest smoothed occupancy that trilinear
  /// sampling anywhere inside it can see (its voxels and a one-voxel margin), i fastest.
  const std::vector<std::uint8_t>& brick_max();
  std::array<int, 3> brick_shape() const;
  static constexpr int kBrickSize = 4;
  /// Normals are the gradient of the smoothed occupancy over a tetrahedron this many voxels
  /// along each axis from the hit.
  static constexpr double kNormalSpan = 1.2;

  /// First crossing of the iso-surface (0..1 on the smoothed occupancy) by the ray origin + t *
  /// direction (volume frame): samples half a voxel apart from where the ray enters the grid,
  /// bisection between the last sample below and the first at or above the level. The label is
  /// that of the voxel a quarter voxel further along the ray, or if that is empty of the solid
  /// voxel with the largest trilinear weight at the hit. (The GPU ray caster does the same.)
  VolumeHit raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                    double iso = 0.5, double max_distance = 1e9);

 private:
  // Boxes edited since the derived fields were last brought up to date, at most this many
  // (beyond, they are merged into one).
  static constexpr std::size_t kStaleBoxes = 64;

  void record(VolumeEdit edit);
  void log_edit(VolumeEdit edit);
  void update_derived();
  void mark_derived_stale(const VoxelBox& box);
  void update_derived_box(const VoxelBox& box);

  std::array<int, 3> shape_;
  Eigen::Vector3d dimensions_;
  LabelType label_type_;
  LabelTable table_;
  std::vector<std::uint8_t> labels_;    // raw bytes, 1 or 2 per voxel
  std::vector<std::uint8_t> original_;  // what reset() restores
  IntensityType intensity_type_ = IntensityType::kNone;
  std::vector<std::uint8_t> intensity_;
  std::int64_t intensity_revision_ = 0;
  Eigen::Matrix4d patient_from_volume_ = Eigen::Matrix4d::Identity();
  std::string source_;

  std::int64_t revision_ = 0;
  std::atomic<StateMutex*> guard_{nullptr};
  std::deque<std::pair<std::int64_t, VoxelBox>> dirty_;  // recent edits, oldest first
  std::int64_t dirty_floor_ = 0;  // edits at or before this revision are no longer listed
  VoxelBox dirty_dropped_;        // the union of the boxes of those edits
  std::deque<VolumeEdit> edit_log_;
  std::size_t edit_log_voxels_ = 0;
  std::int64_t edit_log_dropped_ = 0;

  std::vector<std::uint8_t> smoothed_;
  std::vector<std::uint8_t> bricks_;
  bool derived_ready_ = false;           // smoothed_ and bricks_ computed (then kept up to date)
  std::vector<VoxelBox> derived_stale_;  // edited since they were
};

// --- The derived fields of any part of a grid, from packed boxes of it (i fastest, k
// slowest; `frame` is where a packed box sits in the grid). VolumeData uses them on its whole
// grid, renderers on copies of the boxes edited.

/// The bricks (VolumeData::kBrickSize^3 voxels) whose sampling footprint (the brick and a
/// one-voxel margin) meets `voxels`, in a grid of `shape` voxels.
AMBFPLUS_API VoxelBox bricks_reaching(const VoxelBox& voxels, const std::array<int, 3>& shape);
/// The voxels the footprints of `bricks` cover, in a grid of `shape` voxels.
AMBFPLUS_API VoxelBox brick_footprints(const VoxelBox& bricks, const std::array<int, 3>& shape);
/// Writes the smoothed occupancy (VolumeData::smoothed_occupancy) of `box`, in a grid of
/// `shape`, into `out`, a packed box `out_frame` holding box. `labels` is a packed box
/// `labels_frame` of the label grid (`bytes` 1 or 2 per voxel) that holds every voxel of the
/// grid within VolumeData::kSmoothRadius of box.
AMBFPLUS_API void smooth_occupancy(const std::uint8_t* labels, const VoxelBox& labels_frame,
                                   int bytes, const std::array<int, 3>& shape, const VoxelBox& box,
                                   std::uint8_t* out, const VoxelBox& out_frame);
/// Writes the brick maxima (VolumeData::brick_max) of `bricks`, in a grid of `shape` voxels,
/// into `out`, a packed box `out_frame` of the brick grid holding bricks. `smoothed` is a packed
/// box `smoothed_frame` of the smoothed occupancy that holds brick_footprints(bricks, shape).
AMBFPLUS_API void brick_maxima(const std::uint8_t* smoothed, const VoxelBox& smoothed_frame,
                               const std::array<int, 3>& shape, const VoxelBox& bricks,
                               std::uint8_t* out, const VoxelBox& out_frame);

}  // namespace ambfplus
