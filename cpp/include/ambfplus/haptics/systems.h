#pragma once

// The haptics area's systems of a world (World adds them): input devices and drills.

#include <memory>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus::haptics {

/// Input devices (InputDevice objects): polled devices sampled before a step (in scripted mode;
/// a real-time loop polls them on its slow thread), readings moving the drills in the stage
/// kDeviceInput, the drills' forces sent back in kDeviceOutput.
AMBFPLUS_API std::unique_ptr<System> make_device_system();
/// Drills: one haptic tick each (cursors, forces, removal) in the stage kHaptics.
AMBFPLUS_API std::unique_ptr<System> make_drill_system();

}  // namespace ambfplus::haptics
