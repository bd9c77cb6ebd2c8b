#include "sound_system.h"

#include <algorithm>
#include <cmath>

#include "ambfplus/audio/systems.h"
#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::audio {

DrillTick SoundFeed::tick(std::int64_t step) const {
  DrillTick t;
  const Drill& d = *drill;
  t.on = d.on();
  t.speed = static_cast<float>(d.speed());
  t.load = static_cast<float>(d.force().norm());
  // The voxels this step removed are the newest of the drill's list.
  const auto& removed = d.removed();
  double count = 0.0, hard = 0.0;
  for (auto it = removed.rbegin(); it != removed.rend() && it->step == step; ++it) {
    count += 1.0;
    hard += it->label < hardness.size() ? hardness[it->label] : 1.0;
  }
  const double dt = d.world().time_step();
  t.removal_rate = static_cast<float>(count * voxel_volume / dt);
  t.hardness = count > 0 ? static_cast<float>(hard / count) : 1.0f;
  const auto& warnings = player->spec().warnings;
  const auto& distances = d.critical_distances();
  for (std::size_t i = 0; i < warnings.size(); ++i) {
    for (const auto& [label, distance] : distances) {
      if (label == warnings[i].label) t.distances[i] = static_cast<float>(distance);
    }
  }
  return t;
}

void SoundSystem::object_removed(Object& object) {
  for (auto& feed : feeds_) {
    if (feed->drill == &object) feed->drill = nullptr;
  }
  feeds_.erase(std::remove_if(feeds_.begin(), feeds_.end(),
                              [](const auto& f) { return f->drill == nullptr; }),
               feeds_.end());
}

void SoundSystem::detach_all() {
  for (auto& feed : feeds_) feed->drill = nullptr;
  feeds_.clear();
}

void SoundSystem::detach(const SoundFeed* feed) {
  feeds_.erase(
      std::remove_if(feeds_.begin(), feeds_.end(), [&](const auto& f) { return f.get() == feed; }),
      feeds_.end());
}

void SoundSystem::run(StepStage, const StepContext& context) {
  for (const auto& feed : feeds_) feed->player->push(feed->tick(context.step));
}

std::unique_ptr<System> make_sound_system() { return std::make_unique<SoundSystem>(); }

DrillSound::DrillSound(Drill& drill, DrillSoundSpec spec, const PlayerOptions& options,
                       std::vector<double> hardness)
    : drill_(&drill), world_(&drill.world()) {
  SoundSystem* system = world_->find_system<SoundSystem>();
  if (system == nullptr) {
    throw StateError("DrillSound: world '" + world_->name() +
                     "' has no sound system (a simulator of the engine has one)");
  }
  for (double h : hardness) {
    if (!(std::isfinite(h) && h > 0)) {
      throw ArgumentError("DrillSound: hardness = " + std::to_string(h) + ", expected > 0");
    }
  }
  spec.tick_seconds = world_->time_step();
  player_ = std::make_shared<DrillSoundPlayer>(spec, options);
  feed_ = std::make_shared<SoundFeed>();
  feed_->drill = &drill;
  feed_->player = player_;
  feed_->hardness = std::move(hardness);
  const Eigen::Vector3d voxel = drill.volume().data()->voxel_size();
  feed_->voxel_volume = voxel.x() * voxel.y() * voxel.z();
  auto lock = world_->lock_state();
  system->attach(feed_);
}

DrillSound::~DrillSound() { close(); }

void DrillSound::close() {
  if (closed_) return;
  closed_ = true;
  {
    auto lock = world_->lock_state();
    if (SoundSystem* system = world_->find_system<SoundSystem>()) system->detach(feed_.get());
  }
  player_->close();
}

DrillTick DrillSound::tick_now(std::int64_t step) const {
  if (feed_->drill == nullptr) throw StateError("DrillSound: its drill has left the world");
  return feed_->tick(step);
}

}  // namespace ambfplus::audio
