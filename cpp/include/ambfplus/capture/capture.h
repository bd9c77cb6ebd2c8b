#pragma once

// What a capture is asked for: where its images go and which objects' poses it records. The
// images, the camera's geometry and the poses of one capture all come from one copy of the
// world taken under its state lock, so they belong to one simulation step.

#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/capture/passes.h"
#include "ambfplus/export.h"

namespace ambfplus {

/// Where a capture writes its images; null pointers are not captured.
struct AMBFPLUS_API CaptureBuffers {
  std::uint8_t* rgb = nullptr;           ///< height x width x 3, tightly packed
  float* depth = nullptr;                ///< height x width, tightly packed
  std::uint16_t* label = nullptr;        ///< height x width, tightly packed
  std::int32_t* instance = nullptr;      ///< height x width, tightly packed
  std::int32_t* voxel = nullptr;         ///< height x width, tightly packed
  std::uint8_t* segmentation = nullptr;  ///< height x width x 3, tightly packed
  float* points = nullptr;               ///< height x width x 3, tightly packed
  /// The CapturePass bits of the non-null buffers.
  unsigned passes() const;
};

/// Which objects' poses a capture records beside its images (Frame::poses).
struct AMBFPLUS_API PoseRequest {
  bool all = false;                ///< every object of the world, in creation order
  std::vector<std::string> names;  ///< else these, in this order (an unknown name throws)
  bool empty() const { return !all && names.empty(); }
  /// Every object's pose.
  static PoseRequest every() {
    PoseRequest r;
    r.all = true;
    return r;
  }
};

}  // namespace ambfplus
