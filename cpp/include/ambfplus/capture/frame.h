#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/capture/image_buffer.h"
#include "ambfplus/capture/passes.h"
#include "ambfplus/export.h"

namespace ambfplus {

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
  /// height x width x 3: camera-frame points (x right, y down, z forward) of the pixel centres
  /// at their depth, (0, 0, 0) where nothing was hit.
  ImageBuffer<float> points;

  int width = 0;
  int height = 0;
  double time = 0.0;      ///< simulation time of the capture, seconds
  std::int64_t step = 0;  ///< simulation step index of the capture
  std::string camera;     ///< name of the camera that took it
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  ///< world from camera (OpenCV frame)
  /// The objects' poses asked for (PoseRequest), world from object, of the same step as the
  /// images; every capture replaces them (none when none were asked for).
  struct ObjectPose {
    std::string name;
    int id = 0;
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  };
  std::vector<ObjectPose> poses;
  /// Whether this capture was asked for poses.
  bool has_poses = false;
};

}  // namespace ambfplus
