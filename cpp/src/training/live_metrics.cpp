#include "ambfplus/training/live_metrics.h"

#include <time.h>

#include <algorithm>
#include <limits>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/step_log.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/scene/world.h"
#include "util/clock.h"

namespace ambfplus {
namespace {

using util::thread_cpu_seconds;

}  // namespace

LiveMetrics::LiveMetrics(Drill& drill, MetricsConfig config)
    : drill_(&drill), metrics_(*drill.volume().data(), [&] {
        // The drill removes the voxels itself.
        config.apply_removals = false;
        return std::move(config);
      }()) {}

void LiveMetrics::tick(const StepContext& context) {
  if (drill_ == nullptr) return;
  const double started = thread_cpu_seconds();
  const Drill& d = *drill_;
  tick_.step = context.step;
  tick_.time = context.time;
  tick_.dt = context.dt;
  tick_.tip = tip();
  tick_.force = d.force();
  tick_.burr_radius = d.burr_radius();
  tick_.burr_on = d.on();
  tick_.removed.clear();
  tick_.removed_labels.clear();
  // This step's voxels are the newest of the drill's log.
  const auto& removed = d.removed();
  auto first = removed.end();
  while (first != removed.begin() && std::prev(first)->step == context.step) --first;
  for (auto it = first; it != removed.end(); ++it) {
    tick_.removed.push_back(it->voxel);
    tick_.removed_labels.push_back(it->label);
  }
  metrics_.set_realtime(d.realtime());
  metrics_.add(tick_);
  tick_cpu_seconds_.push_back(thread_cpu_seconds() - started);
  if (tick_cpu_seconds_.size() > kTickHistory) tick_cpu_seconds_.pop_front();
}

Eigen::Vector3d LiveMetrics::tip() const {
  return burr_in_volume(drill_->volume().pose().matrix(), drill_->pose().translation());
}

std::vector<LiveMetrics::Clearance> LiveMetrics::clearances() const {
  std::vector<Clearance> out;
  const auto& protect = metrics_.config().protect;
  for (std::size_t s = 0; s < protect.size(); ++s) {
    const double d = drill_ == nullptr ? std::numeric_limits<double>::infinity()
                                       : metrics_.clearance(s, tip(), drill_->burr_radius());
    out.push_back({protect[s].name, protect[s].margin, d});
  }
  return out;
}

namespace training {
namespace {

class TrainingSystem : public System {
 public:
  const char* name() const override { return "training"; }
  unsigned stages() const override { return stage_bit(StepStage::kHaptics); }
  void object_removed(Object& object) override {
    for (auto& m : metrics_) {
      if (m->active() && &m->drill() == &object) m->detach();
    }
  }
  void detach_all() override {
    for (auto& m : metrics_) m->detach();
  }
  void run(StepStage, const StepContext& context) override {
    for (auto& m : metrics_) m->tick(context);
  }
  // "<drill>.metrics_fields": the protected structures whose updated fields the drill's live
  // metrics took at the step, as bits (structure s: bit s % 48 of value s / 48, an integer
  // exact in a double), so an offline assessment takes them at the same steps.
  void add_step_log_columns(const Object& object, StepLogColumns& columns) const override {
    const LiveMetrics* found = find(object);
    if (found == nullptr) return;
    const std::size_t count = found->metrics().config().protect.size();
    const int width = static_cast<int>(std::max<std::size_t>(1, (count + 47) / 48));
    columns.add("metrics_fields", width, [this, width](const Object& o, std::vector<double>& out) {
      const std::size_t at = out.size();
      out.resize(at + static_cast<std::size_t>(width), 0.0);
      if (const LiveMetrics* m = find(o)) {
        for (int s : m->metrics().fields_taken()) {
          out[at + static_cast<std::size_t>(s / 48)] +=
              static_cast<double>(std::uint64_t{1} << (s % 48));
        }
      }
    });
  }
  LiveMetrics& add(Drill& drill, MetricsConfig config) {
    metrics_.push_back(std::make_unique<LiveMetrics>(drill, std::move(config)));
    return *metrics_.back();
  }
  const LiveMetrics* find(const Object& drill) const {
    for (const auto& m : metrics_) {
      if (m->active() && static_cast<const Object*>(&m->drill()) == &drill) return m.get();
    }
    return nullptr;
  }
  void remove(const LiveMetrics& metrics) {
    metrics_.erase(std::remove_if(metrics_.begin(), metrics_.end(),
                                  [&](const auto& m) { return m.get() == &metrics; }),
                   metrics_.end());
  }

 private:
  std::vector<std::unique_ptr<LiveMetrics>> metrics_;
};

}  // namespace

std::unique_ptr<System> make_training_system() { return std::make_unique<TrainingSystem>(); }

}  // namespace training

LiveMetrics& add_live_metrics(World& world, Drill& drill, MetricsConfig config) {
  auto* system = world.find_system<training::TrainingSystem>();
  if (system == nullptr) {
    throw StateError("world '" + world.name() + "' has no training system (not an engine world)");
  }
  if (&drill.world() != &world) {
    throw ArgumentError("add_live_metrics: drill '" + drill.name() + "' is not in world '" +
                        world.name() + "'");
  }
  auto lock = world.lock_state_for_copy();
  return system->add(drill, std::move(config));
}

void remove_live_metrics(World& world, const LiveMetrics& metrics) {
  auto* system = world.find_system<training::TrainingSystem>();
  if (system == nullptr) return;
  auto lock = world.lock_state_for_copy();
  system->remove(metrics);
}

}  // namespace ambfplus
