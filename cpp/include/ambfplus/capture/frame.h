#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Geometry>

#include "ambfplus/capture/image_buffer.h"
#include "ambfplus/export.h"

namespace ambfplus {

/// The images a capture can render; a camera renders the ones asked for and only those.
enum CapturePass : unsigned {
  kPassRgb = 1u << 0,       ///< lit colour
  kPassDepth = 1u << 1,     ///< metric z
  kPassLabel = 1u << 2,     ///< volume label ids
  kPassInstance = 1u << 3,  ///< object ids
  kPassVoxel = 1u << 4,     ///< volume voxel indices
  /// Flat colours as AMBF's preprocessing shaders draw them: the camera's preprocessing shader
  /// where one is set, else the engine's equivalent (material ambient x light ambient for
  /// meshes, label colours for volumes).
  kPassSegmentation = 1u << 5,
};

/// Number of capture passes; pass i is the bit 1 << i.
constexpr int kPassCount = 6;
/// Every pass.
constexpr unsigned kAllPasses = (1u << kPassCount) - 1;
/// A pass's name as users write it: "rgb", "depth", "label", "instance", "voxel", "segmentation".
AMBFPLUS_API const char* pass_name(int index);

/// One camera capture: images plus the geometry and time they were taken at.
///
/// Conventions: image row 0 is the top; rgb is uint8 RGB; depth is metric z along the optical
/// axis (0 where nothing was hit). The intrinsics map a camera-frame point (x right, y down,
/// z forward) to continuous pixel coordinates in which pixel (row r, column c) covers
/// [c, c+1) x [r, r+1) and is centred at (c + 0.5, r + 0.5).
class AMBFPLUS_API Frame {
 public:
  Frame() = default;
  Frame(Frame&&) noexcept = default;
  Frame& operator=(Frame&&) noexcept = default;

  ImageBuffer<std::uint8_t> rgb;     ///< height x width x 3
  ImageBuffer<float> depth;          ///< height x width
  ImageBuffer<std::uint16_t> label;  ///< height x width: volume label ids, 0 elsewhere
  /// height x width: the id of the object seen (Object::id, meshes and volumes alike), 0 where
  /// nothing was hit.
  ImageBuffer<std::int32_t> instance;
  /// height x width: the linear index (i + nx (j + ny k)) of the volume voxel whose label the
  /// pixel shows, -1 where no volume was hit.
  ImageBuffer<std::int32_t> voxel;
  ImageBuffer<std::uint8_t> segmentation;  ///< height x width x 3, RGB

  int width = 0;
  int height = 0;
  double time = 0.0;      ///< simulation time of the capture, seconds
  std::int64_t step = 0;  ///< simulation step index of the capture
  std::string camera;     ///< name of the camera that took it
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  ///< world from camera (OpenCV frame)
};

}  // namespace ambfplus
