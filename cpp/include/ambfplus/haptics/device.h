#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/export.h"

namespace ambfplus {

/// What a device can do (CHAI3D's specification fields).
struct AMBFPLUS_API DeviceSpec {
  std::string name;
  double max_force = 0.0;         ///< N
  double max_stiffness = 0.0;     ///< N/m
  double max_damping = 0.0;       ///< N s/m
  double workspace_radius = 0.1;  ///< m
};

/// One reading of a device, in its own frame (x right, y up, z towards the user, as seen from
/// the camera it is paired with).
struct AMBFPLUS_API DeviceState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::uint32_t buttons = 0;  ///< bit i set while button i is held

  bool operator==(const DeviceState& o) const {
    return position == o.position && orientation.coeffs() == o.orientation.coeffs() &&
           buttons == o.buttons;
  }
};

/// A haptic or input device: read once per world step before physics, written the force to
/// render after it. Reads and writes come from the thread that steps the world.
class AMBFPLUS_API Device {
 public:
  explicit Device(DeviceSpec spec) : spec_(std::move(spec)) {}
  virtual ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  const DeviceSpec& spec() const { return spec_; }
  /// The state for world step `step` at simulation time `time` (seconds).
  virtual DeviceState read(std::int64_t step, double time) = 0;
  /// The force (N, device frame) to render for the next dt seconds.
  virtual void write(const Eigen::Vector3d& force, double dt) { last_force_ = force; }
  /// The last force written.
  const Eigen::Vector3d& last_force() const { return last_force_; }

  /// True for devices whose samples come from a slow source (a Python callback): the world
  /// calls poll() every poll_every() steps in scripted mode; a real-time loop polls them from
  /// its own low-rate thread, never from the 1 kHz one.
  virtual bool polled() const { return false; }
  virtual int poll_every() const { return 1; }
  /// Refreshes a polled device's sample for simulation time `time`.
  virtual void poll(double time) {}

 protected:
  Eigen::Vector3d last_force_ = Eigen::Vector3d::Zero();

 private:
  DeviceSpec spec_;
};

/// No device: always at the origin, no buttons, forces ignored (CHAI3D's null device's limits).
class AMBFPLUS_API NullDevice final : public Device {
 public:
  NullDevice();
  DeviceState read(std::int64_t, double) override { return {}; }
};

/// The hand a SimulatedDevice models.
struct AMBFPLUS_API SimulatedHand {
  double mass = 0.1;       ///< kg, hand and handle
  double stiffness = 100;  ///< N/m towards the target
  double damping = 2.0;    ///< N s/m
};

/// A hand holding a device, simulated: a point mass pulled towards a target by a spring and a
/// damper (the hand), and pushed by the force the device renders, so contact really stops it.
/// Integrated semi-implicitly with the world's step; deterministic.
class AMBFPLUS_API SimulatedDevice final : public Device {
 public:
  using Hand = SimulatedHand;
  explicit SimulatedDevice(const Hand& hand = Hand(),
                           const Eigen::Vector3d& position = Eigen::Vector3d::Zero());

  /// Where the hand pulls to, how it holds the handle, and the buttons it presses
  /// (thread-safe).
  void set_target(const Eigen::Vector3d& position,
                  const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity(),
                  std::uint32_t buttons = 0);
  DeviceState read(std::int64_t step, double time) override;
  void write(const Eigen::Vector3d& force, double dt) override;

  const Hand& hand() const { return hand_; }
  Eigen::Vector3d position() const;
  Eigen::Vector3d velocity() const;
  /// Kinetic energy of the hand plus the energy stored in its spring, J.
  double energy() const;

 private:
  Hand hand_;
  mutable std::mutex mutex_;
  Eigen::Vector3d x_, v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_;
  Eigen::Quaterniond orientation_ = Eigen::Quaterniond::Identity();
  std::uint32_t buttons_ = 0;
};

/// A scripted device: waypoints (reached by linear interpolation, orientations by slerp,
/// buttons as given at each), or a sampler called every `every` steps whose last sample is held
/// in between (a Python callback: a polled device).
class AMBFPLUS_API ScriptedDevice final : public Device {
 public:
  struct Waypoint {
    double time = 0.0;  ///< seconds after the first read following set_waypoints
    DeviceState state;
  };
  using Sampler = std::function<DeviceState(double time)>;

  ScriptedDevice();
  /// Follows these from now on, then holds the last (thread-safe).
  void set_waypoints(std::vector<Waypoint> waypoints);
  /// Samples sampler(time) every `every` steps instead of waypoints (thread-safe).
  void set_sampler(Sampler sampler, int every = 10);

  DeviceState read(std::int64_t step, double time) override;
  bool polled() const override;
  int poll_every() const override { return every_; }
  void poll(double time) override;

 private:
  mutable std::mutex mutex_;
  std::vector<Waypoint> waypoints_;
  double start_ = std::numeric_limits<double>::quiet_NaN();  // time of the first read
  Sampler sampler_;
  int every_ = 10;
  DeviceState sample_;
};

/// The keyboard as a device, with the original drilling simulator's bindings (GLFW key codes):
/// Ctrl+W/S move up/down, Ctrl+D/A right/left, Ctrl+I/K into/out of the screen by `step`
/// (device frame: x right, y up, z towards the viewer; bind it with the camera as reference to
/// move relative to the view); keypad 8/5 tilt about x, 4/6 turn about y by `angle`; Space
/// toggles button 0 (spin the burr); C presses button 2 (the next burr). Key events come from
/// the window's thread; a press shows in at least one reading even if released before it.
class AMBFPLUS_API KeyboardDevice final : public Device {
 public:
  explicit KeyboardDevice(double step = 0.001, double angle = 0.05235987755982988);
  /// A key event (GLFW key, action 0 release / 1 press / 2 repeat, modifier bits); true when it
  /// is one of the device's keys (thread-safe).
  bool key(int key, int action, int mods);
  DeviceState read(std::int64_t step, double time) override;
  /// Moves the device (to a reset pose, say) without a key (thread-safe).
  void set_state(const DeviceState& state);

 private:
  double step_, angle_;
  std::mutex mutex_;
  DeviceState state_;
  std::uint32_t latched_ = 0;  // presses not yet read
};

/// One logged reading: what a device gave for a step.
struct AMBFPLUS_API DeviceRecord {
  std::int64_t step = 0;
  DeviceState state;
};

/// Plays back logged readings: the reading logged for a step (held until the next logged one).
class AMBFPLUS_API ReplayDevice final : public Device {
 public:
  /// Records in increasing step order; throws std::invalid_argument otherwise.
  explicit ReplayDevice(std::vector<DeviceRecord> records, DeviceSpec spec = {"replay"});
  DeviceState read(std::int64_t step, double time) override;
  /// Steps read beyond the last record.
  std::int64_t steps_past_end() const { return past_end_; }

 private:
  std::vector<DeviceRecord> records_;
  std::int64_t past_end_ = 0;
};

}  // namespace ambfplus
