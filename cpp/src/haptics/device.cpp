#include "ambfplus/haptics/device.h"
#include "ambfplus/errors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ambfplus {

Device::~Device() = default;

NullDevice::NullDevice() : Device({"null", 0.1, 0.1, 0.0, 0.1}) {}

// A Phantom Omni's limits: a hand of that size, with the drill's default stiffness felt 1:1.
SimulatedDevice::SimulatedDevice(const Hand& hand, const Eigen::Vector3d& position)
    : Device({"simulated", 10.0, 1000.0, 5.0, 0.1}), hand_(hand), x_(position), target_(position) {
  if (!(hand.mass > 0) || !(hand.stiffness >= 0) || !(hand.damping >= 0)) {
    throw ArgumentError(
        "simulated device: the hand needs mass > 0, stiffness >= 0 and "
        "damping >= 0");
  }
}

void SimulatedDevice::set_target(const Eigen::Vector3d& position,
                                 const Eigen::Quaterniond& orientation, std::uint32_t buttons) {
  std::lock_guard<std::mutex> lock(mutex_);
  target_ = position;
  orientation_ = orientation.normalized();
  buttons_ = buttons;
}

DeviceState SimulatedDevice::read(std::int64_t, double) {
  std::lock_guard<std::mutex> lock(mutex_);
  return {x_, orientation_, buttons_};
}

void SimulatedDevice::write(const Eigen::Vector3d& force, double dt) {
  last_force_ = force;
  std::lock_guard<std::mutex> lock(mutex_);
  // Semi-implicit Euler: velocity from this step's forces, then position from that velocity.
  const Eigen::Vector3d a =
      (hand_.stiffness * (target_ - x_) - hand_.damping * v_ + force) / hand_.mass;
  v_ += a * dt;
  x_ += v_ * dt;
}

Eigen::Vector3d SimulatedDevice::position() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return x_;
}

Eigen::Vector3d SimulatedDevice::velocity() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return v_;
}

double SimulatedDevice::energy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return 0.5 * hand_.mass * v_.squaredNorm() + 0.5 * hand_.stiffness * (target_ - x_).squaredNorm();
}

ScriptedDevice::ScriptedDevice() : Device({"scripted", 10.0, 1000.0, 5.0, 0.1}) {}

void ScriptedDevice::set_waypoints(std::vector<Waypoint> waypoints) {
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    if (!(waypoints[i].time >= waypoints[i - 1].time)) {
      throw ArgumentError("scripted device: waypoint times must not decrease");
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  waypoints_ = std::move(waypoints);
  for (Waypoint& w : waypoints_) w.state.orientation.normalize();
  start_ = std::numeric_limits<double>::quiet_NaN();
  sampler_ = nullptr;
}

void ScriptedDevice::set_sampler(Sampler sampler, int every) {
  if (every < 1) throw ArgumentError("scripted device: every must be >= 1");
  std::lock_guard<std::mutex> lock(mutex_);
  sampler_ = std::move(sampler);
  every_ = every;
  waypoints_.clear();
}

bool ScriptedDevice::polled() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<bool>(sampler_);
}

void ScriptedDevice::poll(double time) {
  Sampler sampler;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sampler = sampler_;
  }
  if (!sampler) return;
  DeviceState s = sampler(time);  // may take a while (Python): outside the lock
  s.orientation.normalize();
  std::lock_guard<std::mutex> lock(mutex_);
  sample_ = s;
}

DeviceState ScriptedDevice::read(std::int64_t, double time) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (sampler_ || waypoints_.empty()) return sample_;
  if (std::isnan(start_)) start_ = time;
  const double t = time - start_;
  auto after = std::upper_bound(waypoints_.begin(), waypoints_.end(), t,
                                [](double v, const Waypoint& w) { return v < w.time; });
  if (after == waypoints_.begin()) return sample_ = after->state;
  if (after == waypoints_.end()) return sample_ = waypoints_.back().state;
  const Waypoint& a = *(after - 1);
  const Waypoint& b = *after;
  const double f = b.time > a.time ? (t - a.time) / (b.time - a.time) : 1.0;
  sample_.position = a.state.position + f * (b.state.position - a.state.position);
  sample_.orientation = a.state.orientation.slerp(f, b.state.orientation);
  sample_.buttons = a.state.buttons;
  return sample_;
}

namespace {
// GLFW's key codes and modifier bits, which key events carry.
constexpr int kKeySpace = 32, kKeyA = 65, kKeyC = 67, kKeyD = 68, kKeyI = 73, kKeyK = 75,
              kKeyS = 83, kKeyW = 87, kKeyPad4 = 324, kKeyPad5 = 325, kKeyPad6 = 326,
              kKeyPad8 = 328;
constexpr int kModControl = 0x2;
constexpr int kRelease = 0;
}  // namespace

KeyboardDevice::KeyboardDevice(double step, double angle)
    : Device({"keyboard", 10.0, 1000.0, 5.0, 0.1}), step_(step), angle_(angle) {
  if (!(step > 0) || !(angle > 0)) {
    throw ArgumentError("keyboard device: step and angle must be > 0");
  }
}

bool KeyboardDevice::key(int key, int action, int mods) {
  const bool control = (mods & kModControl) != 0;
  const bool down = action != kRelease;
  std::lock_guard<std::mutex> lock(mutex_);
  if (control) {
    Eigen::Vector3d move = Eigen::Vector3d::Zero();
    switch (key) {
      case kKeyW:
        move.y() = step_;
        break;
      case kKeyS:
        move.y() = -step_;
        break;
      case kKeyD:
        move.x() = step_;
        break;
      case kKeyA:
        move.x() = -step_;
        break;
      case kKeyI:
        move.z() = -step_;
        break;
      case kKeyK:
        move.z() = step_;
        break;
      default:
        return false;
    }
    if (down) state_.position += move;
    return true;
  }
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  double turn = angle_;
  switch (key) {
    case kKeyPad8:
      axis = Eigen::Vector3d::UnitX();
      turn = -angle_;
      break;
    case kKeyPad5:
      axis = Eigen::Vector3d::UnitX();
      break;
    case kKeyPad4:
      axis = Eigen::Vector3d::UnitY();
      turn = -angle_;
      break;
    case kKeyPad6:
      axis = Eigen::Vector3d::UnitY();
      break;
    case kKeySpace:
      if (action == 1) state_.buttons ^= 1u;  // a toggle: presses only, not repeats
      return true;
    case kKeyC: {
      const std::uint32_t next = 1u << 2;
      if (action == 1) {
        state_.buttons |= next;
        latched_ |= next;
      } else if (action == kRelease) {
        state_.buttons &= ~next;
      }
      return true;
    }
    default:
      return false;
  }
  if (down) {
    state_.orientation = (Eigen::AngleAxisd(turn, axis) * state_.orientation).normalized();
  }
  return true;
}

DeviceState KeyboardDevice::read(std::int64_t, double) {
  std::lock_guard<std::mutex> lock(mutex_);
  DeviceState s = state_;
  s.buttons |= latched_;
  latched_ = 0;
  return s;
}

void KeyboardDevice::set_state(const DeviceState& state) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_ = state;
  state_.orientation.normalize();
}

MergedDevice::MergedDevice(std::shared_ptr<Device> pose,
                           std::vector<std::shared_ptr<Device>> buttons)
    : Device(pose ? pose->spec() : DeviceSpec{}),
      pose_(std::move(pose)),
      buttons_(std::move(buttons)) {
  if (!pose_) throw ArgumentError("merged device: needs a device for the pose");
  for (const auto& b : buttons_) {
    if (!b) throw ArgumentError("merged device: a button device is missing");
  }
}

DeviceState MergedDevice::read(std::int64_t step, double time) {
  DeviceState s = pose_->read(step, time);
  for (const auto& b : buttons_) s.buttons |= b->read(step, time).buttons;
  return s;
}

void MergedDevice::write(const Eigen::Vector3d& force, double dt) {
  last_force_ = force;
  pose_->write(force, dt);
}

ReplayDevice::ReplayDevice(std::vector<DeviceRecord> records, DeviceSpec spec)
    : Device(std::move(spec)), records_(std::move(records)) {
  for (std::size_t i = 1; i < records_.size(); ++i) {
    if (records_[i].step <= records_[i - 1].step) {
      throw ArgumentError("replay device: record " + std::to_string(i) + " has step " +
                          std::to_string(records_[i].step) + ", not after " +
                          std::to_string(records_[i - 1].step));
    }
  }
}

DeviceState ReplayDevice::read(std::int64_t step, double) {
  if (records_.empty()) return {};
  if (step > records_.back().step) ++past_end_;
  const auto after =
      std::upper_bound(records_.begin(), records_.end(), step,
                       [](std::int64_t s, const DeviceRecord& r) { return s < r.step; });
  return after == records_.begin() ? records_.front().state : (after - 1)->state;
}

}  // namespace ambfplus
