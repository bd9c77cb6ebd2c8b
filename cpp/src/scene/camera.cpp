#include "ambfplus/scene/camera.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "ambfplus/scene/world.h"

namespace ambfplus {

Camera::Camera(Model& model, const CameraSpec& spec, int id)
    : Object(model, spec.name, id),
      width_(spec.width),
      height_(spec.height),
      fov_y_(spec.fov_y),
      near_(spec.near),
      far_(spec.far),
      cx_(spec.width / 2.0),
      cy_(spec.height / 2.0),
      shadows_(spec.shadows),
      antialiasing_(spec.antialiasing),
      looks_(spec.looks),
      background_(spec.background),
      publish_(spec.publish) {
  spec.validate();
  set_pose(checked_pose(spec.pose));
}

void Camera::look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                     const Eigen::Vector3d& up) {
  if (!eye.allFinite() || !target.allFinite() || !up.allFinite()) {
    throw ArgumentError("camera '" + name() + "': look_at needs finite eye, target and up");
  }
  const Eigen::Vector3d forward = target - eye;
  if (!(forward.norm() > 0.0)) {
    throw ArgumentError("camera '" + name() + "': look_at needs target != eye");
  }
  const Eigen::Vector3d z = forward.normalized();
  // OpenCV frame: x right, y down, z forward. Image up (-y) follows `up` projected on the image.
  const Eigen::Vector3d right = z.cross(up);
  if (!(right.norm() > 1e-9 * up.norm()) || !(up.norm() > 0.0)) {
    throw ArgumentError("camera '" + name() +
                        "': look_at needs an up vector not parallel to the view direction");
  }
  const Eigen::Vector3d x = right.normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  set_pose(pose);
}

Eigen::Matrix3d Camera::intrinsics() const {
  const double f = height_ / (2.0 * std::tan(fov_y_ / 2.0));
  Eigen::Matrix3d k;
  k << f, 0, cx_, 0, f, cy_, 0, 0, 1;
  return k;
}

void Camera::set_principal_point(double cx, double cy) {
  if (!std::isfinite(cx) || !std::isfinite(cy)) {
    throw ArgumentError("camera '" + name() + "': the principal point must be finite");
  }
  cx_ = cx;
  cy_ = cy;
}

void Camera::set_fov_y(double fov_y) {
  if (!(fov_y > 0.0 && fov_y < M_PI)) {
    throw ArgumentError("camera '" + name() + "': fov_y must be in (0, pi) radians, got " +
                        std::to_string(fov_y));
  }
  fov_y_ = fov_y;
}

void check_antialiasing(const std::string& camera, int k) {
  if (k < 1 || k > kMaxAntialiasing) {
    throw ArgumentError("camera '" + camera + "': antialiasing must be 1 (off) to " +
                        std::to_string(kMaxAntialiasing) + ", got " + std::to_string(k));
  }
}

void Camera::set_antialiasing(int k) {
  check_antialiasing(name(), k);
  antialiasing_ = k;
}

void Camera::set_passes(unsigned passes) {
  if (passes == 0 || (passes & ~kAllPasses) != 0) {
    throw ArgumentError("camera '" + name() + "': passes must be a non-empty set of " +
                        pass_names(kAllPasses));
  }
  passes_ = passes;
}

Eigen::Matrix4d Camera::projection() const {
  // Reversed z (near -> 1, far -> 0) with a zero-to-one clip range keeps a float depth buffer
  // precise at every distance. x and y map continuous pixel coordinates straight to window
  // coordinates, so GL's bottom-up row order reads back with image row 0 first.
  const Eigen::Matrix3d k = intrinsics();
  const double w = width_, h = height_, n = near_, f = far_;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2 * k(0, 0) / w;
  p(0, 2) = 2 * k(0, 2) / w - 1;
  p(1, 1) = 2 * k(1, 1) / h;
  p(1, 2) = 2 * k(1, 2) / h - 1;
  p(2, 2) = -n / (f - n);
  p(2, 3) = n * f / (f - n);
  p(3, 2) = 1;
  return p;
}

}  // namespace ambfplus
