#pragma once

#include <memory>
#include <vector>

#include "ambfplus/audio/drill_sound.h"
#include "ambfplus/scene/system.h"

namespace ambfplus::audio {

/// What a step needs to feed one player from one drill.
struct SoundFeed {
  Drill* drill = nullptr;  // null once the drill left the world
  std::shared_ptr<DrillSoundPlayer> player;
  std::vector<double> hardness;  // by label
  double voxel_volume = 0.0;     // m^3
  DrillTick tick(std::int64_t step) const;
};

/// Feeds every attached player from its drill, after the drills' tick.
class SoundSystem : public System {
 public:
  const char* name() const override { return "sound"; }
  unsigned stages() const override { return stage_bit(StepStage::kHaptics); }
  void object_removed(Object& object) override;
  void detach_all() override;
  void run(StepStage stage, const StepContext& context) override;

  /// Under the world's state lock.
  void attach(std::shared_ptr<SoundFeed> feed) { feeds_.push_back(std::move(feed)); }
  void detach(const SoundFeed* feed);

 private:
  std::vector<std::shared_ptr<SoundFeed>> feeds_;
};

}  // namespace ambfplus::audio
