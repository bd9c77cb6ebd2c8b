#pragma once

// Skill metrics measured live: a drill's state fed to SkillMetrics at every step of its world,
// by the training system (the same code the offline assessment of a recording runs).

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"
#include "ambfplus/training/skill_metrics.h"

namespace ambfplus {

class Drill;
class World;

/// The metrics of one drill, fed at every step of its world after the drills have ticked: the
/// burr's centre in its volume's frame, the force fed back, the burr, whether it spins and the
/// voxels it removed in the step (which the drill has already taken from the volume, so the
/// structures' distance fields follow the drilling). Read it under the world's lock while a
/// real-time loop steps. Its fields follow the drilling: in a real-time loop a field is taken
/// when it is ready (never waited for), and the step log's "<drill>.metrics_fields" says at
/// which step, so that the offline assessment of the recording takes it at the same step and
/// equals the live metrics exactly; scripted, on the offline schedule.
class AMBFPLUS_API LiveMetrics {
 public:
  LiveMetrics(Drill& drill, MetricsConfig config);
  Drill& drill() const { return *drill_; }
  /// One step: called by the training system.
  void tick(const StepContext& context);
  MetricsSummary summary() const { return metrics_.summary(); }
  const SkillMetrics& metrics() const { return metrics_; }
  /// Each protected structure's distance (metres) from the burr where it is now, with its
  /// margin, in the config's order (infinite once the structure is gone).
  struct Clearance {
    std::string name;
    double margin = 0.0;
    double distance = 0.0;
  };
  std::vector<Clearance> clearances() const;
  /// CPU time of the thread for the last ticks (up to kTickHistory), seconds: what the metrics
  /// add to a haptic tick.
  const std::deque<double>& tick_cpu_seconds() const { return tick_cpu_seconds_; }
  static constexpr std::size_t kTickHistory = 16384;
  /// Whether its drill is still in the world (a removed drill's metrics stop).
  bool active() const { return drill_ != nullptr; }
  void detach() { drill_ = nullptr; }

 private:
  Eigen::Vector3d tip() const;  // the burr's centre, volume frame
  Drill* drill_;
  SkillMetrics metrics_;
  ToolTick tick_;
  std::deque<double> tick_cpu_seconds_;
};

/// Starts live metrics of `drill` in its world (the world's training system feeds them); the
/// world owns them. Throws ArgumentError for a bad config.
AMBFPLUS_API LiveMetrics& add_live_metrics(World& world, Drill& drill, MetricsConfig config);
/// Stops them (they are destroyed).
AMBFPLUS_API void remove_live_metrics(World& world, const LiveMetrics& metrics);

namespace training {
/// The system that feeds live metrics (stage kHaptics, after the drills).
AMBFPLUS_API std::unique_ptr<System> make_training_system();
}  // namespace training

}  // namespace ambfplus
