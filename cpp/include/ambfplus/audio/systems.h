#pragma once

// The audio area's system of a world (the engine adds it): drill sounds fed at every step.

#include <memory>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus::audio {

/// Drill sounds (DrillSound): each fed one tick per step in the stage kHaptics, after the
/// drills have ticked.
AMBFPLUS_API std::unique_ptr<System> make_sound_system();

}  // namespace ambfplus::audio
