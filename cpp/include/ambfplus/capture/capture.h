#pragma once

// What a capture is asked for: where its images go and which objects' poses it records. The
// images, the camera's geometry and the poses of one capture all come from one copy of the
// world taken under its state lock, so they belong to one simulation step.

#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/capture/frame.h"
#include "ambfplus/capture/passes.h"
#include "ambfplus/export.h"

namespace ambfplus {

class Camera;

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

/// Renders a camera's view into a new frame that owns its images (the camera's passes).
AMBFPLUS_API Frame capture_frame(const Camera& camera, const PoseRequest& poses = {});
/// Renders into an existing frame: its buffers are reused (filled in place) and must match the
/// camera's size. A frame without buffers gets the camera's passes; one with buffers is refilled
/// with exactly those. Throws ArgumentError on a mismatch.
AMBFPLUS_API void capture_into(const Camera& camera, Frame& frame, const PoseRequest& poses = {});
/// Renders into caller-owned memory and fills frame's metadata and poses (its buffers are left
/// alone).
AMBFPLUS_API void capture_into(const Camera& camera, const CaptureBuffers& buffers, Frame& frame,
                               const PoseRequest& poses = {});
/// Allocates in an empty frame the buffers of these passes (CapturePass bits) at the camera's
/// size.
AMBFPLUS_API void allocate_frame(const Camera& camera, Frame& frame, unsigned passes);

}  // namespace ambfplus
