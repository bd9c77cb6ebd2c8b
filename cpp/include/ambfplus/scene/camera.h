#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "ambfplus/capture/passes.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/shader_spec.h"

namespace ambfplus {

/// What an ADF asks a camera to publish (AMBF's keys and defaults); recorders read it.
struct AMBFPLUS_API CameraPublish {
  bool image = false;        ///< `publish image`
  int image_interval = 1;    ///< `publish image interval`: every n-th render
  bool depth = false;        ///< `publish depth`
  int depth_interval = 10;   ///< `publish depth interval`
  bool depth_noise = false;  ///< `publish depth noise` given
  double noise_mean = 0.1, noise_std = 0.001, noise_bias = 0.0;  ///< its mean, std_dev, bias
};

/// The largest rgb antialiasing level (Camera::set_antialiasing).
constexpr int kMaxAntialiasing = 4;

/// Throws ArgumentError naming the camera unless k is an antialiasing level (1..4).
void check_antialiasing(const std::string& camera, int k);

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
  CameraPublish publish;
  bool shadows = false;  ///< lights cast shadows in the rgb pass (see Camera::shadows)
  int antialiasing = 1;  ///< rgb antialiasing, 1 (off) to 4 (Camera::antialiasing)
  bool looks = false;    ///< volume surface looks in the rgb pass (see Camera::looks)

  /// Throws ArgumentError naming the camera and the value unless every value can be used (size
  /// 1..16384, fov_y in (0, pi), 0 < near < far, a rigid pose, background in 0..1, intervals
  /// >= 1).
  void validate() const;
};

/// add_camera's keyword options: width, height, fov_y, near, far, pose, background, shadows,
/// antialiasing, looks.
AMBFPLUS_API const OptionTable<CameraSpec>& camera_options();

/// A pinhole camera in the OpenCV frame (x right, y down, z forward). pose() is world from camera.
/// The camera describes a view; capture/capture.h renders it (capture_frame, capture_into).
class AMBFPLUS_API Camera : public Object {
 public:
  ObjectKind kind() const override { return ObjectKind::kCamera; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fov_y() const { return fov_y_; }
  double near() const { return near_; }
  double far() const { return far_; }
  const std::array<float, 3>& background() const { return background_; }
  const CameraPublish& publish() const { return publish_; }

  /// Places the camera at eye looking at target; up fixes the roll (image up points along it).
  void look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  /// fx = fy = H / (2 tan(fov_y / 2)); (cx, cy) the principal point, W / 2, H / 2 unless moved
  /// (see Frame for the pixel convention).
  Eigen::Matrix3d intrinsics() const;
  /// Moves the principal point (pixels): an off-axis camera, e.g. one of a stereo pair whose
  /// views converge at a working distance. The image plane stays parallel.
  void set_principal_point(double cx, double cy);
  /// Changes the vertical field of view (radians, in (0, pi)); the principal point stays.
  void set_fov_y(double fov_y);
  Eigen::Vector2d principal_point() const { return {cx_, cy_}; }

  /// The passes a capture into a new frame makes (CapturePass bits; default kDefaultPasses).
  unsigned passes() const { return passes_; }
  void set_passes(unsigned passes);
  /// AMBF's `preprocessing shaders`: what the segmentation pass draws meshes with (volumes keep
  /// their label colours); unset or empty: the engine's equivalent of AMBF's own.
  const std::optional<ShaderSpec>& preprocessing_shader() const { return preprocessing_shader_; }
  void set_preprocessing_shader(std::optional<ShaderSpec> shader) {
    preprocessing_shader_ = std::move(shader);
  }

  /// OpenGL clip from camera (OpenCV frame), mapping image row 0 to the first row read back.
  Eigen::Matrix4d projection() const;

  /// Whether the rgb pass draws shadows of the lights whose shadow_quality is above 0
  /// (directional and spot lights). Ground-truth passes never change.
  bool shadows() const { return shadows_; }
  void set_shadows(bool on) { shadows_ = on; }
  /// The rgb pass's antialiasing: 1 is off; 2 to 4 supersample each pixel where edges or
  /// contrast need it: 2 blends its centre (1/2) with its four corners (1/8 each; corners are
  /// shared with the neighbouring pixels), 3 and 4 take the mean of a k x k grid of samples.
  /// Ground-truth passes stay one exact sample at each pixel centre. ArgumentError outside 1..4.
  int antialiasing() const { return antialiasing_; }
  void set_antialiasing(int k);
  /// Whether the rgb pass gives volumes their surface looks: ambient occlusion from the
  /// occupancy, a world-fixed bone texture (or the CT intensity where the volume has one) and a
  /// wet specular highlight. Ground-truth passes never change.
  bool looks() const { return looks_; }
  void set_looks(bool on) { looks_ = on; }

 private:
  friend class Model;
  Camera(Model& model, const CameraSpec& spec, int id);

  int width_;
  int height_;
  double fov_y_;
  double near_;
  double far_;
  double cx_, cy_;
  unsigned passes_ = kDefaultPasses;
  bool shadows_ = false;
  int antialiasing_ = 1;
  bool looks_ = false;
  std::array<float, 3> background_;
  CameraPublish publish_;
  std::optional<ShaderSpec> preprocessing_shader_;
};

}  // namespace ambfplus
