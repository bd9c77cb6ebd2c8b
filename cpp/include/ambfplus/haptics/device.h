#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
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

/// A device on the network: a bridge process (a proprietary haptic SDK, a recorded trajectory)
/// sends poses over UDP and receives the force to render, so no SDK links into the engine.
///
/// Messages are little-endian datagrams. Pose, bridge to engine, exactly 80 bytes:
///   0 magic "APDP", 4 uint16 version (1), 6 uint16 reserved (0), 8 uint64 sequence (increasing),
///   16 float64 x3 position (m, device frame), 40 float64 x4 orientation (x, y, z, w; unit to
///   1e-3, renormalised), 72 uint32 buttons, 76 uint32 reserved (0).
/// Force, engine to the sender of the last accepted pose, 48 bytes, after every step:
///   0 magic "APDF", 4 uint16 version (1), 6 uint16 reserved, 8 uint64 sequence of the pose it
///   answers, 16 float64 simulation time (s), 24 float64 x3 force (N, device frame).
/// Anything else (another size, magic or version, non-finite numbers, a position farther than
/// `max_distance`, a quaternion that is not a rotation, a sequence not after the last accepted
/// one) is rejected and counted by reason; the last accepted reading stays in force. Readings
/// are relative to the first accepted pose (position minus its position, orientation times its
/// inverse), so a bridge's device takes the drill up where it is, as a clutch would.
class AMBFPLUS_API NetworkDevice final : public Device {
 public:
  static constexpr std::size_t kPoseBytes = 80, kForceBytes = 48;
  /// Binds UDP `port` (0: any free port, see port()) on `address` (loopback unless another
  /// address is given on purpose). Throws Error naming the address if it cannot.
  explicit NetworkDevice(int port = 0, const std::string& address = "127.0.0.1",
                         double max_distance = 10.0);
  ~NetworkDevice() override;

  int port() const { return port_; }
  DeviceState read(std::int64_t step, double time) override;
  void write(const Eigen::Vector3d& force, double dt) override;
  /// Poses accepted, and messages rejected by reason ("size", "magic", "version", "values",
  /// "range", "rotation", "sequence").
  std::uint64_t accepted() const;
  std::vector<std::pair<std::string, std::uint64_t>> rejected() const;
  /// Checks a datagram; the reading it carries, or the reason it is refused.
  static bool parse(const std::uint8_t* data, std::size_t size, double max_distance,
                    DeviceState& state, std::uint64_t& sequence, std::string& reason);

 private:
  void receive();

  int socket_ = -1;
  int port_ = 0;
  double max_distance_;
  double time_ = 0.0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  DeviceState state_;
  Eigen::Vector3d origin_position_ = Eigen::Vector3d::Zero();
  Eigen::Quaterniond origin_orientation_ = Eigen::Quaterniond::Identity();
  std::uint64_t sequence_ = 0;
  bool has_client_ = false;
  std::uint8_t client_[128] = {};  // sockaddr_storage of the last sender
  unsigned client_size_ = 0;
  std::uint64_t accepted_ = 0;
  std::vector<std::pair<std::string, std::uint64_t>> rejected_;
};

/// Which joystick buttons and axes do what (JoystickDevice).
struct AMBFPLUS_API JoystickMapping {
  int drill = 0;                      ///< joystick button held: the burr spins (device button 0)
  int clutch = 1;                     ///< held: clutch (device button 1)
  int burr = 2;                       ///< pressed: the next burr (device button 2)
  std::array<int, 3> axes{0, 1, -1};  ///< joystick axis moving x, y, z (-1: none)
  double speed = 0.02;                ///< m/s at full deflection
  double deadband = 0.05;             ///< of full deflection
};

/// A joystick, gamepad or foot pedal through the Linux joystick interface (/dev/input/jsN):
/// buttons take roles (held: the burr spins, held: clutch, pressed: the next burr) and axes move
/// the device at `speed` m/s at full deflection (x right, y up, z towards the user). Events come
/// from the device file on a thread of its own, or from feed() (tests, other sources).
class AMBFPLUS_API JoystickDevice final : public Device {
 public:
  using Mapping = JoystickMapping;
  /// Without a path: events only through feed().
  explicit JoystickDevice(const std::string& path = "", Mapping mapping = Mapping());
  ~JoystickDevice() override;

  /// Linux js_event records (8 bytes each: uint32 time ms, int16 value, uint8 type, uint8
  /// number); a partial record waits for the rest.
  void feed(const std::uint8_t* data, std::size_t size);
  DeviceState read(std::int64_t step, double time) override;
  const Mapping& mapping() const { return mapping_; }
  /// The device file failed (unplugged): every button is released and the device stands still.
  bool disconnected() const;

 private:
  void event(std::int16_t value, std::uint8_t type, std::uint8_t number);
  void listen();

  Mapping mapping_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::vector<std::uint8_t> partial_;
  bool disconnected_ = false;
  std::array<double, 3> deflection_{0, 0, 0};
  std::uint32_t held_ = 0, latched_ = 0;  // device buttons
  DeviceState state_;
  double last_time_ = -1;
};

/// A pose from one device and buttons from others (a haptic device with a foot pedal).
class AMBFPLUS_API MergedDevice final : public Device {
 public:
  MergedDevice(std::shared_ptr<Device> pose, std::vector<std::shared_ptr<Device>> buttons);
  DeviceState read(std::int64_t step, double time) override;
  void write(const Eigen::Vector3d& force, double dt) override;
  bool polled() const override { return pose_->polled(); }
  int poll_every() const override { return pose_->poll_every(); }
  void poll(double time) override { pose_->poll(time); }

 private:
  std::shared_ptr<Device> pose_;
  std::vector<std::shared_ptr<Device>> buttons_;
};

/// One logged reading: what a device gave for a step.
struct AMBFPLUS_API DeviceRecord {
  std::int64_t step = 0;
  DeviceState state;
};

/// Plays back logged readings: the reading logged for a step (held until the next logged one).
class AMBFPLUS_API ReplayDevice final : public Device {
 public:
  /// Records in increasing step order; throws ArgumentError otherwise. By default it limits no
  /// force (it renders none): a replay reproduces the recorded session's limit through its
  /// binding's max_force.
  explicit ReplayDevice(std::vector<DeviceRecord> records,
                        DeviceSpec spec = {"replay", std::numeric_limits<double>::infinity()});
  DeviceState read(std::int64_t step, double time) override;
  /// Steps read beyond the last record.
  std::int64_t steps_past_end() const { return past_end_; }

 private:
  std::vector<DeviceRecord> records_;
  std::int64_t past_end_ = 0;
};

}  // namespace ambfplus
