// body_spinner: an object plugin that turns its rigid body about the body's own z axis, one
// turn every four seconds of simulation time, and cycles its colour through the hues as it
// goes, so both show in every capture. Reset puts it back where it started.

#include <array>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "ambfplus/log.h"
#include "ambfplus/plugin/plugin.h"
#include "ambfplus/scene/rigid_body.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSecondsPerTurn = 4.0;

class BodySpinner : public ambfplus::Plugin {
 public:
  int init() override {
    body_ = dynamic_cast<ambfplus::RigidBody*>(object());
    if (body_ == nullptr) {
      ambfplus::log(ambfplus::LogLevel::kWarning,
                    "body_spinner '" + name() +
                        "' turns rigid bodies: declare it in a body's "
                        "block (object scope); it is not kept here");
      return 0;
    }
    // Moved by this plugin only, so physics does not fight it.
    body_->set_kinematic(true);
    start_ = body_->pose();
    start_color_ = body_->material().color;
    return 1;
  }

  void physics_update(double dt) override {
    angle_ = std::fmod(angle_ + 2 * kPi * dt / kSecondsPerTurn, 2 * kPi);
    body_->set_pose(start_ * Eigen::AngleAxisd(angle_, Eigen::Vector3d::UnitZ()));
  }

  void graphics_update() override {
    ambfplus::Material material = body_->material();
    const double hue = angle_ / (2 * kPi);
    for (int c = 0; c < 3; ++c) {
      // A fully saturated colour: each channel a shifted triangle wave of the hue.
      const double t = std::fmod(hue + c / 3.0, 1.0);
      material.color[c] =
          static_cast<float>(std::fmin(1.0, std::fmax(0.0, std::fabs(t * 6 - 3) - 1)));
    }
    body_->set_material(material);
  }

  void reset() override {
    angle_ = 0;
    body_->set_pose(start_);
    ambfplus::Material material = body_->material();
    material.color = start_color_;
    body_->set_material(material);
  }

 private:
  ambfplus::RigidBody* body_ = nullptr;
  // Members of the plugin's own class may be Eigen types: only the plugin's code lays it out.
  Eigen::Isometry3d start_ = Eigen::Isometry3d::Identity();
  std::array<float, 4> start_color_{};
  double angle_ = 0;
};

}  // namespace

AMBFPLUS_PLUGIN(BodySpinner)
