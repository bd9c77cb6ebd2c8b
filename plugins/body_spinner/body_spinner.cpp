// body_spinner: an object plugin that turns its rigid body about the body's own z axis, one
// turn every four seconds of simulation time, and cycles its colour through the hues as it
// goes, so both show in every capture. Reset puts it back where it started.

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/plugin/plugin.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSecondsPerTurn = 4.0;

// The engine passes poses as row-major double[16]; Eigen, in this plugin's own code, is
// column-major: copy through a row-major map.
using RowMajor4d = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

Eigen::Isometry3d from_engine(const ambfplus::plugin::Pose& p) {
  Eigen::Isometry3d pose;
  pose.matrix() = Eigen::Map<const RowMajor4d>(p.data());
  return pose;
}

ambfplus::plugin::Pose to_engine(const Eigen::Isometry3d& pose) {
  ambfplus::plugin::Pose p;
  Eigen::Map<RowMajor4d>(p.data()) = pose.matrix();
  return p;
}

class BodySpinner : public ambfplus::plugin::Plugin {
 public:
  int init() override {
    body_ = object();
    if (!body_ || body_.kind() != AMBFPLUS_BODY) {
      ambfplus_log(AMBFPLUS_WARNING, ("body_spinner '" + name() +
                                      "' turns rigid bodies: declare it in a body's block (object "
                                      "scope); it is not kept here")
                                         .c_str());
      return 0;
    }
    // Moved by this plugin only, so physics does not fight it.
    body_.set1("kinematic", 1.0);
    start_ = from_engine(body_.pose());
    start_color_ = body_.get("color");
    return 1;
  }

  void physics_update(double dt) override {
    angle_ = std::fmod(angle_ + 2 * kPi * dt / kSecondsPerTurn, 2 * kPi);
    body_.set_pose(to_engine(start_ * Eigen::AngleAxisd(angle_, Eigen::Vector3d::UnitZ())));
  }

  void graphics_update() override {
    std::vector<double> color = body_.get("color");
    const double hue = angle_ / (2 * kPi);
    for (int c = 0; c < 3; ++c) {
      // A fully saturated colour: each channel a shifted triangle wave of the hue.
      const double t = std::fmod(hue + c / 3.0, 1.0);
      color[c] = std::fmin(1.0, std::fmax(0.0, std::fabs(t * 6 - 3) - 1));
    }
    body_.set("color", color);
  }

  void reset() override {
    angle_ = 0;
    body_.set_pose(to_engine(start_));
    body_.set("color", start_color_);
  }

 private:
  ambfplus::plugin::Object body_;
  // Members of the plugin's own class may be Eigen types: only the plugin's code lays it out.
  Eigen::Isometry3d start_ = Eigen::Isometry3d::Identity();
  std::vector<double> start_color_;
  double angle_ = 0;
};

}  // namespace

AMBFPLUS_PLUGIN(BodySpinner)
