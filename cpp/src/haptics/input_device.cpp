#include "ambfplus/haptics/input_device.h"
#include "ambfplus/errors.h"

#include <algorithm>
#include <stdexcept>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

InputDevice& add_input_device(Model& model, const InputDeviceSpec& spec) {
  auto lock = model.world().lock_state();  // claim, build and adopt as one
  if (spec.drill != nullptr && &spec.drill->world() != &model.world()) {
    throw ArgumentError("input device '" + spec.name + "': its drill is in another world");
  }
  const int id = model.claim_name(spec.name, "input device");
  return model.adopt(std::unique_ptr<InputDevice>(new InputDevice(model, spec, id)));
}

InputDevice::InputDevice(Model& model, const InputDeviceSpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string who = "input device '" + spec.name + "': ";
  if (!spec_.device) throw ArgumentError(who + "needs a device");
  if (spec_.drill == nullptr) throw ArgumentError(who + "needs a drill to drive");
  spec_.validate();
}

Eigen::Matrix3d InputDevice::reference_rotation() const {
  if (spec_.reference == nullptr) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d r = spec_.reference->pose().linear();
  if (spec_.reference->kind() != ObjectKind::kCamera) return r;
  // A camera's image: x right, y up, z towards the viewer (its OpenCV y and z turned over).
  return r * Eigen::Vector3d(1, -1, -1).asDiagonal();
}

void InputDevice::pre_step(std::int64_t step, double time) {
  const DeviceState previous = state_;
  state_ = spec_.device->read(step, time);
  log_.push_back({step, state_});
  if (log_.size() > kMaxLog) {
    log_.pop_front();
    ++log_dropped_;
  }
  const std::uint32_t pressed = state_.buttons & ~previous.buttons;
  Drill& drill = *spec_.drill;
  clutched_ = held(spec_.clutch_button);
  if (started_ && !clutched_) {
    const Eigen::Matrix3d r = reference_rotation();
    Eigen::Isometry3d goal = drill.goal();
    goal.translation() += spec_.workspace_scale * (r * (state_.position - previous.position));
    const Eigen::Quaterniond turn = state_.orientation * previous.orientation.inverse();
    // Renormalised through a quaternion, so rounding does not build up over a long session.
    goal.linear() = Eigen::Quaterniond(r * turn.toRotationMatrix() * r.transpose() * goal.linear())
                        .normalized()
                        .toRotationMatrix();
    drill.set_goal(goal);
  }
  started_ = true;
  if (spec_.drill_button >= 0) drill.set_on(held(spec_.drill_button));
  if (spec_.burr_button >= 0 && spec_.burr_button < 32 && ((pressed >> spec_.burr_button) & 1u)) {
    const int n = static_cast<int>(drill.spec().burr_diameters.size());
    drill.set_burr((drill.burr() + 1) % n);
  }
}

void InputDevice::post_step(double dt) {
  Eigen::Vector3d f = spec_.force_scale * (reference_rotation().transpose() * spec_.drill->force());
  const double limit = std::min(spec_.max_force, spec_.device->spec().max_force);
  if (f.norm() > limit) f *= limit / f.norm();
  force_ = f;
  spec_.device->write(f, dt);
}

std::deque<DeviceRecord> InputDevice::take_log() {
  std::deque<DeviceRecord> out;
  out.swap(log_);
  return out;
}

}  // namespace ambfplus
