#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "ambfplus/haptics/device.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class Drill;

/// Everything needed to let a device drive a drill.
struct AMBFPLUS_API InputDeviceSpec {
  std::string name;
  std::shared_ptr<Device> device;
  Drill* drill = nullptr;        ///< what it drives
  double workspace_scale = 1.0;  ///< world metres per device metre (AMBF's `workspace scaling`)
  /// Device motion is along this object's axes (a camera, AMBF's `pair cameras`: x right, y
  /// up, z towards the viewer on its image); nullptr: the world's axes.
  const Object* reference = nullptr;
  int drill_button = 0;   ///< held: the burr spins (-1: none)
  int clutch_button = 1;  ///< held: the device moves without moving the drill (-1: none)
  int burr_button = -1;   ///< pressed: the next burr (-1: none)
  /// Largest force sent to the device, N; infinity: the device's own maximum.
  double max_force = std::numeric_limits<double>::infinity();
  double force_scale = 1.0;  ///< force sent per newton of the drill's force

  /// Throws ArgumentError naming the input device and the value unless every value can be used
  /// (workspace scale > 0, max force and force scale >= 0, buttons -1..31); its device and
  /// drill are the constructor's to check.
  void validate() const;
};

/// add_input_device's keyword options: workspace_scale, reference, drill_button, clutch_button,
/// burr_button, max_force, force_scale.
AMBFPLUS_API const OptionTable<InputDeviceSpec>& input_device_options();

class InputDevice;
/// Creates an input device in a model, bound to a drill of the same world. Throws ArgumentError
/// for a bad spec, a drill of another world or a taken name.
AMBFPLUS_API InputDevice& add_input_device(Model& model, const InputDeviceSpec& spec);

/// A device bound to a drill, as a surgeon holds it: each step, before physics, the device's
/// motion since the previous reading moves the drill's goal, scaled by the workspace scale and
/// turned into the reference's current axes (so a camera moving alone does not move the drill);
/// while the clutch is held the device moves alone (indexing). Its buttons turn the burr and
/// change it. After the step the drill's force goes back to the device, in the device's axes.
/// Every reading is logged with its step, so a session replays exactly from its log
/// (ReplayDevice).
class AMBFPLUS_API InputDevice : public Object {
 public:
  ObjectKind kind() const override { return ObjectKind::kInputDevice; }
  const std::shared_ptr<Device>& device() const { return spec_.device; }
  const InputDeviceSpec& spec() const { return spec_; }
  Drill* drill() const { return spec_.drill; }

  /// Reads the device and moves the drill (the world calls it before physics).
  void pre_step(std::int64_t step, double time);
  /// Sends the drill's force to the device (the world calls it after the drill's tick).
  void post_step(double dt);

  /// Readings since the last take_log(), oldest first: the newest kMaxLog (a minute at 1 kHz,
  /// about 6 MB) are kept, older ones dropped and counted; a recorder takes them more often.
  const std::deque<DeviceRecord>& log() const { return log_; }
  std::deque<DeviceRecord> take_log();
  static constexpr std::size_t kMaxLog = 65536;
  /// Readings dropped because nobody took them in time.
  std::int64_t log_dropped() const { return log_dropped_; }
  /// The last reading.
  const DeviceState& state() const { return state_; }
  bool clutched() const { return clutched_; }
  /// The force sent to the device after the last step, N (device frame).
  const Eigen::Vector3d& force() const { return force_; }

 private:
  friend InputDevice& add_input_device(Model& model, const InputDeviceSpec& spec);
  InputDevice(Model& model, const InputDeviceSpec& spec, int id);
  Eigen::Matrix3d reference_rotation() const;
  bool held(int button) const {
    return button >= 0 && button < 32 && ((state_.buttons >> button) & 1u) != 0;
  }

  InputDeviceSpec spec_;
  DeviceState state_;
  bool started_ = false;  // a reading was taken (state_ holds the previous one)
  bool clutched_ = false;
  Eigen::Vector3d force_ = Eigen::Vector3d::Zero();
  std::deque<DeviceRecord> log_;
  std::int64_t log_dropped_ = 0;
};

}  // namespace ambfplus
