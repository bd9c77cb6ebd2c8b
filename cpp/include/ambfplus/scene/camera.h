#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "ambfplus/capture/frame.h"
#include "ambfplus/scene/object.h"

namespace ambfplus {

/// Everything needed to create a camera. Defaults are AMBF's (fva 0.7 rad, near 0.1, far 10).
struct AMBFPLUS_API CameraSpec {
  std::string name;
  int width = 640;
  int height = 480;
  double fov_y = 0.7;  ///< vertical field of view, radians
  double near = 0.1;   ///< metres
  double far = 10.0;   ///< metres
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  std::array<float, 3> background{0.0f, 0.0f, 0.0f};  ///< RGB, 0..1, where nothing is hit
};

/// Where a capture writes its images; null pointers are not captured.
struct CaptureBuffers {
  std::uint8_t* rgb = nullptr;     ///< height x width x 3, tightly packed
  float* depth = nullptr;          ///< height x width, tightly packed
  std::uint16_t* label = nullptr;  ///< height x width, tightly packed
};

/// A pinhole camera in the OpenCV frame (x right, y down, z forward). pose() is world from camera.
class AMBFPLUS_API Camera : public Object {
 public:
  ObjectKind kind() const override { return ObjectKind::kCamera; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fov_y() const { return fov_y_; }
  double near() const { return near_; }
  double far() const { return far_; }
  const std::array<float, 3>& background() const { return background_; }

  /// Places the camera at eye looking at target; up fixes the roll (image up points along it).
  void look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  /// fx = fy = H / (2 tan(fov_y / 2)), cx = W / 2, cy = H / 2 (see Frame for the pixel convention).
  Eigen::Matrix3d intrinsics() const;
  /// OpenGL clip from camera (OpenCV frame), mapping image row 0 to the first row read back.
  Eigen::Matrix4d projection() const;

  /// Renders and returns a new frame that owns its images.
  Frame capture();
  /// Renders into an existing frame: its buffers are reused (filled in place) and must match
  /// this camera's size; empty ones are allocated. Throws std::invalid_argument on a mismatch.
  void capture(Frame& frame);
  /// Renders into caller-owned memory and fills frame's metadata (its buffers are left alone).
  void capture(const CaptureBuffers& buffers, Frame& frame);

 private:
  friend class Model;
  Camera(Model& model, const CameraSpec& spec, int id);

  int width_;
  int height_;
  double fov_y_;
  double near_;
  double far_;
  std::array<float, 3> background_;
};

}  // namespace ambfplus
