#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ambfplus/export.h"
#include "ambfplus/volume/distance_field.h"
#include "ambfplus/volume/structure_distances.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// A structure the trainee must not touch, watched through its distance field.
struct AMBFPLUS_API ProtectedStructure {
  std::string name;
  std::vector<std::uint16_t> labels;
  /// Safety margin (metres): the burr's surface closer than this is a contact.
  double margin = 0.001;
};

/// What the metrics are measured against: the structures to protect, the target region and the
/// thresholds that turn a measurement into an event.
struct AMBFPLUS_API MetricsConfig {
  std::vector<ProtectedStructure> protect;
  /// Labels whose voxels make the target region (empty: no target by label).
  std::vector<std::uint16_t> target_labels;
  /// Or the target region voxel by voxel: one byte per voxel of the volume, i fastest (non-zero:
  /// in the target). When given, it alone says what is in the target.
  std::vector<std::uint8_t> target_mask;
  /// A force magnitude (N) above which cutting counts as excessive.
  double excess_force = 3.0;
  /// A stroke ends after the burr has not cut for this long (seconds).
  double stroke_gap = 0.05;
  /// A stroke's direction is sampled every this many metres of its path; a turn of more than
  /// turn_angle (radians) between two samples is a direction change.
  double turn_step = 0.0005;
  double turn_angle = 0.7853981633974483;
  /// Distance fields reach this far (metres) beyond the largest margin.
  double field_band = 0.005;
  /// Offline: the metrics remove each tick's voxels from their volume themselves (a copy of the
  /// anatomy as the recording began), so that the fields follow the drilling as they did live.
  bool apply_removals = false;
};

/// One haptic tick as the metrics see it.
struct AMBFPLUS_API ToolTick {
  std::int64_t step = 0;
  double time = 0.0;                                ///< seconds, at the end of the step
  double dt = 0.001;                                ///< the step's length, seconds
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();    ///< burr centre, volume frame, metres
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< force on the hand, newtons
  double burr_radius = 0.0;                         ///< metres
  bool burr_on = false;
  /// Voxels removed during the step, with the labels they had.
  std::vector<std::array<int, 3>> removed;
  std::vector<std::uint16_t> removed_labels;
  /// Replaying a real-time session: `scheduled` ticks take exactly the updated fields of the
  /// protected structures (indices into MetricsConfig::protect) in `take_fields`, those the live
  /// metrics took at this tick (SkillMetrics::fields_taken, the step log's
  /// "<drill>.metrics_fields"), and no other.
  bool scheduled = false;
  std::vector<int> take_fields;
};

/// The metrics of one protected structure.
struct AMBFPLUS_API StructureMetrics {
  std::string name;
  double margin = 0.0;
  std::int64_t voxels_removed = 0;
  /// Entries of the burr into the margin, and the time spent inside it (seconds).
  std::int64_t contacts = 0;
  double time_in_margin = 0.0;
  /// Least distance (metres) from the burr's surface to the structure (negative: inside it),
  /// the step and time it happened, and where the burr's centre was.
  double closest = 0.0;
  std::int64_t closest_step = -1;
  double closest_time = 0.0;
  /// The force (N) while inside the margin: mean and largest magnitude.
  double force_in_margin_mean = 0.0;
  double force_in_margin_max = 0.0;
  /// The largest burr diameter (metres) used inside the margin (0: never inside).
  double burr_diameter_in_margin = 0.0;
  /// The first step at which a voxel of the structure was removed (-1: never), and its time.
  std::int64_t first_breach_step = -1;
  double first_breach_time = 0.0;
};

/// One continuous cutting segment.
struct AMBFPLUS_API Stroke {
  std::int64_t first_step = 0;
  std::int64_t last_step = 0;
  double duration = 0.0;      ///< seconds
  double length = 0.0;        ///< path length of the burr centre, metres
  double straightness = 1.0;  ///< chord / length (1: a straight line)
  std::int64_t direction_changes = 0;
  std::int64_t voxels = 0;  ///< removed during it
};

/// Everything measured so far.
struct AMBFPLUS_API MetricsSummary {
  std::int64_t ticks = 0;
  double total_time = 0.0;
  double burr_on_time = 0.0;
  double cutting_time = 0.0;  ///< time of steps that removed at least one voxel
  double voxel_volume = 0.0;  ///< cubic metres per voxel
  /// Voxels removed per label id (index = id).
  std::vector<std::int64_t> removed_by_label;
  std::int64_t removed_in_target = 0;
  std::int64_t removed_outside_target = 0;
  /// Force magnitude while cutting (N).
  double cutting_force_mean = 0.0;
  double cutting_force_p95 = 0.0;
  double cutting_force_max = 0.0;
  double time_above_excess_force = 0.0;
  /// Removed volume inside the target per minute of cutting (cubic metres per minute).
  double efficiency = 0.0;
  std::vector<StructureMetrics> structures;
  std::vector<Stroke> strokes;
};

/// The burr's centre in the volume's frame, from the volume's pose and the burr's position in the
/// world. The live metrics and an offline replay of a recording both take their ticks' centres
/// from here, so that both compare the same bits (a near tie between two ticks' clearances must
/// not fall differently).
AMBFPLUS_API Eigen::Vector3d burr_in_volume(const Eigen::Matrix4d& world_from_volume,
                                            const Eigen::Vector3d& burr_in_world);

/// Skill metrics of a drilling session, computed tick by tick: live in the haptic loop (each
/// tick costs a distance-field sample per protected structure and a few additions) and offline
/// from a recording, by feeding the recorded ticks to the same code. The volume is the one being
/// drilled: the distance fields follow its edits, so a structure exposed or drilled into is
/// measured as it is at that tick.
class AMBFPLUS_API SkillMetrics {
 public:
  /// Throws ArgumentError for a structure without labels, a negative or non-finite margin or
  /// threshold, or two structures with one name.
  SkillMetrics(VolumeData& volume, MetricsConfig config);

  /// Adds one tick (ticks come in order of step). With apply_removals, throws StateError when a
  /// removed voxel's recorded label is not the one the volume holds (another anatomy).
  void add(const ToolTick& tick);
  /// The metrics so far (closes any stroke in progress in the copy it returns).
  MetricsSummary summary() const;
  const MetricsConfig& config() const { return config_; }
  /// The distance (metres) from a sphere of radius r at p (volume frame) to structure s's
  /// surface, from its field as of the last tick: what the contacts are measured with. Beyond
  /// the field's band (margin + field_band) it reads as the band.
  double clearance(std::size_t s, const Eigen::Vector3d& p, double r) const;
  /// A structure's field brought up to date after a breach is taken
  /// StructureDistances::kFollowTicks ticks after the breach, waited for when not yet built
  /// (scripted stepping: deterministic). In real time (a RealTimeLoop, which must never block)
  /// it is taken at the first tick after it is ready instead; the ticks that took one say so
  /// (fields_taken, logged by the step log), and an offline replay given them (ToolTick's
  /// take_fields) takes each field at the same tick, so the live metrics equal the offline
  /// assessment of the session's recording on any machine.
  void set_realtime(bool realtime) { realtime_ = realtime; }
  bool realtime() const { return realtime_; }
  /// The protected structures (indices into MetricsConfig::protect) whose updated fields the
  /// last tick took into use.
  const std::vector<int>& fields_taken() const { return fields_taken_; }
  /// Due fields not yet built when a tick had to take them (scripted, or a replayed schedule),
  /// and the seconds (wall clock) waited for them.
  std::int64_t field_waits() const;
  double field_wait_seconds() const;

 private:
  struct Watch {
    int key = 0;  // the structure's key in distances_
    double band = 0.0;
    StructureMetrics metrics;
    bool inside = false;
    double force_sum = 0.0;
    std::int64_t force_ticks = 0;
  };
  struct OpenStroke {
    bool open = false;
    Stroke stroke;
    Eigen::Vector3d start = Eigen::Vector3d::Zero(), last = Eigen::Vector3d::Zero();
    Eigen::Vector3d sample = Eigen::Vector3d::Zero();  // where the direction was last sampled
    Eigen::Vector3d heading = Eigen::Vector3d::Zero();
    double last_cut_time = 0.0;
  };
  static void close(OpenStroke& open, std::vector<Stroke>& strokes);

  VolumeData& volume_;
  MetricsConfig config_;
  std::vector<bool> in_target_;  // by label id
  // The protected structures' fields, following the drilling off the caller's thread (a breach
  // costs a local update of tens of milliseconds, too long for a haptic tick).
  std::unique_ptr<StructureDistances> distances_;
  std::vector<Watch> watches_;
  MetricsSummary sum_;
  std::vector<float> cutting_forces_;
  double cutting_force_sum_ = 0.0;
  OpenStroke stroke_;
  bool have_tick_ = false;
  bool realtime_ = false;
  std::vector<int> fields_taken_;
};

}  // namespace ambfplus
