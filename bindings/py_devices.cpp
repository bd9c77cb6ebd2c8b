#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/haptics/device.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"
#include "ambfplus/log.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/realtime.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/step_log.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;

// An orientation from Python: None (identity), a quaternion (x, y, z, w) or a 3x3 rotation.
Eigen::Quaterniond to_quaternion(const py::handle& value) {
  if (value.is_none()) return Eigen::Quaterniond::Identity();
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) throw py::type_error("orientation must be a quaternion (x, y, z, w) or a 3x3 matrix");
  if (a.ndim() == 1 && a.shape(0) == 4) {
    const Eigen::Quaterniond q(a.at(3), a.at(0), a.at(1), a.at(2));
    if (!(q.norm() > 1e-9)) throw py::value_error("orientation: the quaternion is zero");
    return q.normalized();
  }
  if (a.ndim() == 2 && a.shape(0) == 3 && a.shape(1) == 3) {
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = a.at(i, j);
    if (!(r.transpose() * r).isIdentity(1e-6) || r.determinant() < 0) {
      throw py::value_error("orientation: the 3x3 matrix is not a rotation");
    }
    return Eigen::Quaterniond(r).normalized();
  }
  throw py::value_error("orientation must be a quaternion (x, y, z, w) or a 3x3 matrix");
}

py::array_t<double> xyzw(const Eigen::Quaterniond& q) {
  py::array_t<double> out(4);
  auto o = out.mutable_unchecked<1>();
  o(0) = q.x();
  o(1) = q.y();
  o(2) = q.z();
  o(3) = q.w();
  return out;
}

py::dict state_dict(const DeviceState& s) {
  py::dict d;
  d["position"] = Vec3(s.position);
  d["orientation"] = xyzw(s.orientation);
  d["buttons"] = s.buttons;
  return d;
}

// A reading from a dict {position, orientation, buttons} or a tuple (position[, orientation[,
// buttons]]).
DeviceState to_state(const py::handle& value, const char* what) {
  DeviceState s;
  py::object position, orientation = py::none(), buttons = py::int_(0);
  if (py::isinstance<py::dict>(value)) {
    auto d = py::reinterpret_borrow<py::dict>(value);
    for (auto item : d) {
      const std::string key = py::str(item.first);
      if (key != "position" && key != "orientation" && key != "buttons" && key != "time") {
        throw py::value_error(std::string(what) + ": unknown key '" + key +
                              "' (expected position, orientation, buttons)");
      }
    }
    if (!d.contains("position")) throw py::value_error(std::string(what) + " needs 'position'");
    position = d["position"];
    if (d.contains("orientation")) orientation = d["orientation"];
    if (d.contains("buttons")) buttons = d["buttons"];
  } else if (py::isinstance<py::tuple>(value) || py::isinstance<py::list>(value)) {
    auto t = py::reinterpret_borrow<py::sequence>(value);
    if (py::len(t) < 1 || py::len(t) > 3) {
      throw py::value_error(std::string(what) + ": expected (position[, orientation[, buttons]])");
    }
    position = t[0];
    if (py::len(t) > 1) orientation = t[1];
    if (py::len(t) > 2) buttons = t[2];
  } else {
    throw py::type_error(std::string(what) +
                         " must be a dict {position, orientation, buttons} or a tuple");
  }
  s.position = position.cast<Vec3>();
  if (!s.position.allFinite()) throw py::value_error(std::string(what) + ": position not finite");
  s.orientation = to_quaternion(orientation);
  const long long b = buttons.cast<long long>();
  if (b < 0 || b > 0xffffffffLL)
    throw py::value_error(std::string(what) + ": buttons out of range");
  s.buttons = static_cast<std::uint32_t>(b);
  return s;
}

py::dict log_arrays(const std::deque<DeviceRecord>& log) {
  const auto n = static_cast<py::ssize_t>(log.size());
  py::array_t<std::int64_t> step(n);
  py::array_t<double> position({n, py::ssize_t(3)});
  py::array_t<double> orientation({n, py::ssize_t(4)});
  py::array_t<std::uint32_t> buttons(n);
  auto s = step.mutable_unchecked<1>();
  auto p = position.mutable_unchecked<2>();
  auto q = orientation.mutable_unchecked<2>();
  auto b = buttons.mutable_unchecked<1>();
  py::ssize_t i = 0;
  for (const DeviceRecord& r : log) {
    s(i) = r.step;
    for (int a = 0; a < 3; ++a) p(i, a) = r.state.position[a];
    q(i, 0) = r.state.orientation.x();
    q(i, 1) = r.state.orientation.y();
    q(i, 2) = r.state.orientation.z();
    q(i, 3) = r.state.orientation.w();
    b(i) = r.state.buttons;
    ++i;
  }
  py::dict d;
  d["step"] = step;
  d["position"] = position;
  d["orientation"] = orientation;
  d["buttons"] = buttons;
  return d;
}

std::vector<DeviceRecord> records_from(const py::dict& log) {
  for (const char* key : {"step", "position", "orientation", "buttons"}) {
    if (!log.contains(key)) {
      throw py::value_error(std::string("a device log needs '") + key +
                            "' (as InputDevice.log gives it)");
    }
  }
  auto step = py::array_t<std::int64_t, py::array::forcecast>::ensure(log["step"]);
  auto position = py::array_t<double, py::array::forcecast>::ensure(log["position"]);
  auto orientation = py::array_t<double, py::array::forcecast>::ensure(log["orientation"]);
  auto buttons = py::array_t<std::int64_t, py::array::forcecast>::ensure(log["buttons"]);
  if (!step || !position || !orientation || !buttons || step.ndim() != 1) {
    throw py::value_error("a device log's entries must be numeric arrays");
  }
  const py::ssize_t n = step.shape(0);
  if (position.ndim() != 2 || position.shape(0) != n || position.shape(1) != 3 ||
      orientation.ndim() != 2 || orientation.shape(0) != n || orientation.shape(1) != 4 ||
      buttons.ndim() != 1 || buttons.shape(0) != n) {
    throw py::value_error(
        "a device log needs step (N,), position (N, 3), orientation (N, 4) and "
        "buttons (N,) of one length N");
  }
  std::vector<DeviceRecord> out(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    DeviceRecord& r = out[static_cast<std::size_t>(i)];
    r.step = step.at(i);
    r.state.position = Vec3(position.at(i, 0), position.at(i, 1), position.at(i, 2));
    r.state.orientation = Eigen::Quaterniond(orientation.at(i, 3), orientation.at(i, 0),
                                             orientation.at(i, 1), orientation.at(i, 2));
    r.state.buttons = static_cast<std::uint32_t>(buttons.at(i));
  }
  return out;
}

py::dict spec_dict(const DeviceSpec& s) {
  py::dict d;
  d["name"] = s.name;
  d["max_force"] = s.max_force;
  d["max_stiffness"] = s.max_stiffness;
  d["max_damping"] = s.max_damping;
  d["workspace_radius"] = s.workspace_radius;
  return d;
}

// Destroys a loop with the GIL released: its polling thread may be waiting for the GIL.
struct ReleaseGilDelete {
  void operator()(RealTimeLoop* loop) const {
    py::gil_scoped_release release;
    delete loop;
  }
};
using LoopHolder = std::unique_ptr<RealTimeLoop, ReleaseGilDelete>;

// Holds a world's state lock for a `with` block (acquired with the GIL released).
struct StateLock {
  std::shared_ptr<World> world;
  std::unique_lock<StateMutex> lock;
};

py::dict stats_dict(const RealTimeStats& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["seconds"] = s.seconds;
  d["mean_rate"] = s.mean_rate;
  d["p99"] = s.p99;
  d["max"] = s.max;
  d["over_2ms"] = s.over_2ms;
  d["step_cpu_p99"] = s.step_p99;
  d["step_cpu_max"] = s.step_cpu_max;
  d["step_wall_max"] = s.step_wall_max;
  d["lock_wait_max"] = s.lock_wait_max;
  d["lock_wait_p99"] = s.lock_wait_p99;
  d["late"] = s.late;
  d["late_step_wall"] = s.late_step_wall;
  d["late_step_cpu"] = s.late_step_cpu;
  d["periods"] = py::array_t<double>(static_cast<py::ssize_t>(s.periods.size()), s.periods.data());
  return d;
}

// A step log's rows as NumPy columns: step (int64), time, and each "<object>.<field>" (N, width),
// (N,) for one value or (N, 4, 4) for poses; flags bool, indices int32, buttons uint32, the rest
// float64.
py::dict step_log_arrays(const StepLog& log) {
  const auto n = static_cast<py::ssize_t>(log.rows());
  py::dict d;
  d["step"] = py::array_t<std::int64_t>(n, log.steps().data());
  d["time"] = py::array_t<double>(n, log.times().data());
  auto ends_with = [](const std::string& s, const char* end) {
    const std::string e(end);
    return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
  };
  for (const StepLog::Column& c : log.columns()) {
    py::array_t<double> values =
        c.width == 1 ? py::array_t<double>(n, c.values.data())
                     : py::array_t<double>({n, static_cast<py::ssize_t>(c.width)}, c.values.data());
    py::object column = values;
    if (c.width == 16) {
      column = values.attr("reshape")(n, 4, 4);  // poses: 4x4 row by row
    } else if (ends_with(c.name, ".on")) {
      column = values.attr("astype")("bool");
    } else if (ends_with(c.name, ".burr") || ends_with(c.name, ".leading")) {
      column = values.attr("astype")("int32");
    } else if (ends_with(c.name, ".buttons")) {
      column = values.attr("astype")("uint32");
    }
    d[py::str(c.name)] = column;
  }
  return d;
}

}  // namespace

void register_world_io(py::class_<World, std::shared_ptr<World>>& world) {
  // Input events reach the plugins under the world's lock (a real-time loop may be stepping).
  world
      .def(
          "keyboard",
          [](World& w, int key, int scancode, int action, int mods) {
            py::gil_scoped_release release;
            auto lock = w.lock_state();
            w.plugins().keyboard(key, scancode, action, mods);
          },
          py::arg("key"), py::arg("scancode"), py::arg("action"), py::arg("mods"),
          "Gives the plugins a key event (GLFW codes).")
      .def(
          "mouse_button",
          [](World& w, int button, int action, int mods) {
            py::gil_scoped_release release;
            auto lock = w.lock_state();
            w.plugins().mouse_button(button, action, mods);
          },
          py::arg("button"), py::arg("action"), py::arg("mods"))
      .def(
          "mouse_move",
          [](World& w, double x, double y) {
            py::gil_scoped_release release;
            auto lock = w.lock_state();
            w.plugins().mouse_move(x, y);
          },
          py::arg("x"), py::arg("y"))
      .def(
          "mouse_scroll",
          [](World& w, double dx, double dy) {
            py::gil_scoped_release release;
            auto lock = w.lock_state();
            w.plugins().mouse_scroll(dx, dy);
          },
          py::arg("dx"), py::arg("dy"));
  world
      .def(
          "start_step_log",
          [](World& w, const std::vector<Object*>& objects) {
            std::vector<const Object*> logged(objects.begin(), objects.end());
            py::gil_scoped_release release;
            w.start_step_log(logged);
          },
          py::arg("objects"),
          "Logs every step's state of these objects from now on (poses; drills: goal, force, "
          "on, burr; input devices: readings and force); take_step_log() drains it.")
      .def(
          "stop_step_log",
          [](World& w) {
            py::gil_scoped_release release;
            w.stop_step_log();
          },
          "Stops logging steps (rows not taken are dropped).")
      .def(
          "take_step_log",
          [](World& w) {
            StepLog log(std::vector<const Object*>{});
            {
              py::gil_scoped_release release;
              log = w.take_step_log();
            }
            return step_log_arrays(log);
          },
          "The steps logged since the last call: {'step', 'time', '<object>.<field>': ...}.");
}

py::object state_lock(World& world) { return py::cast(StateLock{handle(&world, world), {}}); }

InputDevice& add_input_device(Model& model, const std::string& name,
                              const std::shared_ptr<Device>& device, Drill& drill,
                              const py::kwargs& kw) {
  InputDeviceSpec spec;
  spec.name = name;
  spec.device = device;
  spec.drill = &drill;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "workspace_scale") {
      spec.workspace_scale = v.cast<double>();
    } else if (key == "reference") {
      spec.reference = v.is_none() ? nullptr : &v.cast<Object&>();
    } else if (key == "drill_button") {
      spec.drill_button = v.cast<int>();
    } else if (key == "clutch_button") {
      spec.clutch_button = v.cast<int>();
    } else if (key == "burr_button") {
      spec.burr_button = v.cast<int>();
    } else if (key == "max_force") {
      spec.max_force = v.cast<double>();
    } else if (key == "force_scale") {
      spec.force_scale = v.cast<double>();
    } else {
      throw py::type_error("add_input_device() got an unknown option '" + key +
                           "' (expected workspace_scale, reference, drill_button, "
                           "clutch_button, burr_button, max_force, force_scale)");
    }
  }
  if (spec.reference != nullptr && &spec.reference->world() != &model.world()) {
    throw py::value_error("add_input_device(): the reference is in another world");
  }
  return model.add_input_device(spec);
}

void register_devices(py::module_& m,
                      py::class_<InputDevice, Object, std::shared_ptr<InputDevice>>& input) {
  py::class_<Device, std::shared_ptr<Device>>(
      m, "Device",
      "A haptic or input device, read once per world step and sent the force to render.")
      .def_property_readonly(
          "spec", [](Device& d) { return spec_dict(d.spec()); },
          "name, max_force (N), max_stiffness (N/m), max_damping (N s/m), workspace_radius (m)")
      .def_property_readonly(
          "last_force", [](Device& d) { return Vec3(d.last_force()); },
          "the force last sent to it, N, device frame");

  py::class_<NullDevice, Device, std::shared_ptr<NullDevice>>(
      m, "NullDevice", "No device: at the origin, no buttons, forces ignored.")
      .def(py::init<>());

  py::class_<SimulatedDevice, Device, std::shared_ptr<SimulatedDevice>>(
      m, "SimulatedDevice",
      "A hand holding a device, simulated: a mass pulled to a target by a spring and damper and "
      "pushed by the rendered force, so contact stops it. Deterministic.")
      .def(py::init([](double mass, double stiffness, double damping, const Vec3& position) {
             return std::make_shared<SimulatedDevice>(SimulatedHand{mass, stiffness, damping},
                                                      position);
           }),
           py::arg("mass") = 0.1, py::arg("stiffness") = 100.0, py::arg("damping") = 2.0,
           py::arg("position") = Vec3::Zero(),
           "mass (kg), stiffness (N/m) and damping (N s/m) of the hand; its starting position (m).")
      .def(
          "set_target",
          [](SimulatedDevice& d, const Vec3& position, const py::object& orientation,
             std::uint32_t buttons) {
            d.set_target(position, to_quaternion(orientation), buttons);
          },
          py::arg("position"), py::arg("orientation") = py::none(), py::arg("buttons") = 0,
          "Where the hand pulls to (m, device frame), how it holds the handle (quaternion x, y, "
          "z, w or 3x3) and the buttons it holds (bit i: button i). Thread-safe.")
      .def_property_readonly("position", &SimulatedDevice::position, "m, device frame")
      .def_property_readonly("velocity", &SimulatedDevice::velocity, "m/s")
      .def_property_readonly("energy", &SimulatedDevice::energy,
                             "kinetic energy plus the energy in the hand's spring, J");

  py::class_<ScriptedDevice, Device, std::shared_ptr<ScriptedDevice>>(
      m, "ScriptedDevice",
      "A device following waypoints, or a Python callback sampled every `every` steps.")
      .def(py::init<>())
      .def(
          "set_waypoints",
          [](ScriptedDevice& d, const py::list& waypoints) {
            std::vector<ScriptedDevice::Waypoint> w;
            for (const py::handle& item : waypoints) {
              if (!py::isinstance<py::dict>(item) || !item.cast<py::dict>().contains("time")) {
                throw py::value_error(
                    "a waypoint is a dict {time, position, orientation, buttons}");
              }
              w.push_back(
                  {item.cast<py::dict>()["time"].cast<double>(), to_state(item, "waypoint")});
            }
            d.set_waypoints(std::move(w));
          },
          py::arg("waypoints"),
          "[{time (s after the first step that reads them), position, orientation, buttons}]: "
          "positions interpolated linearly, orientations by slerp, buttons as at the last "
          "waypoint passed; the last is held.")
      .def(
          "set_callback",
          [](ScriptedDevice& d, py::function callback, int every) {
            // Holds the callable through a shared_ptr whose deleter takes the GIL, since the
            // sampler may be destroyed on a thread without it.
            auto fn = std::shared_ptr<py::function>(new py::function(std::move(callback)),
                                                    [](py::function* f) {
                                                      py::gil_scoped_acquire gil;
                                                      delete f;
                                                    });
            d.set_sampler(
                [fn](double time) {
                  py::gil_scoped_acquire gil;
                  return to_state((*fn)(time), "the device callback's result");
                },
                every);
          },
          py::arg("callback"), py::arg("every") = 10,
          "callback(time) -> {position, orientation, buttons} or (position[, orientation[, "
          "buttons]]), called every `every` steps (in a real-time loop from its low-rate "
          "thread); the reading is held in between.");

  py::class_<KeyboardDevice, Device, std::shared_ptr<KeyboardDevice>>(
      m, "KeyboardDevice",
      "The keyboard as a device, with the original drilling simulator's bindings: Ctrl+W/S/D/A/"
      "I/K move by `step` (up, down, right, left, into and out of the screen of the reference "
      "camera), keypad 8/5 and 4/6 turn by `angle`, Space toggles the burr (button 0), C takes "
      "the next burr (button 2).")
      .def(py::init<double, double>(), py::arg("step") = 0.001,
           py::arg("angle") = 0.05235987755982988)
      .def("key", &KeyboardDevice::key, py::arg("key"), py::arg("action"), py::arg("mods"),
           "A key event (GLFW key code, action 0 release / 1 press / 2 repeat, modifier bits); "
           "True when it is one of the device's keys.")
      .def(
          "set_state",
          [](KeyboardDevice& d, const py::object& state) { d.set_state(to_state(state, "state")); },
          py::arg("state"), "Sets the reading ({position, orientation, buttons}).");

  py::class_<NetworkDevice, Device, std::shared_ptr<NetworkDevice>>(
      m, "NetworkDevice",
      "A device on the network: a bridge sends 80-byte UDP pose datagrams and gets 48-byte "
      "force datagrams back after every step (format in ambfplus/haptics/device.h and "
      "README); bound to loopback unless another address is given. Malformed, oversized or "
      "stale messages are rejected and counted.")
      .def(py::init([](int port, const std::string& address, double max_distance) {
             py::gil_scoped_release release;
             return std::make_shared<NetworkDevice>(port, address, max_distance);
           }),
           py::arg("port") = 0, py::arg("address") = "127.0.0.1", py::arg("max_distance") = 10.0)
      .def_property_readonly("port", &NetworkDevice::port, "the bound UDP port")
      .def_property_readonly("accepted", &NetworkDevice::accepted, "poses accepted")
      .def_property_readonly(
          "rejected",
          [](NetworkDevice& d) {
            py::dict out;
            for (const auto& [reason, count] : d.rejected()) out[py::str(reason)] = count;
            return out;
          },
          "messages rejected, by reason (size, magic, version, values, range, rotation, "
          "sequence)");

  py::class_<JoystickDevice::Mapping>(m, "JoystickMapping",
                                      "Which joystick buttons and axes do what.")
      .def(py::init([](int drill, int clutch, int burr, std::array<int, 3> axes, double speed,
                       double deadband) {
             return JoystickMapping{drill, clutch, burr, axes, speed, deadband};
           }),
           py::arg("drill") = 0, py::arg("clutch") = 1, py::arg("burr") = 2,
           py::arg("axes") = std::array<int, 3>{0, 1, -1}, py::arg("speed") = 0.02,
           py::arg("deadband") = 0.05)
      .def_readonly("drill", &JoystickDevice::Mapping::drill)
      .def_readonly("clutch", &JoystickDevice::Mapping::clutch)
      .def_readonly("burr", &JoystickDevice::Mapping::burr)
      .def_readonly("axes", &JoystickDevice::Mapping::axes)
      .def_readonly("speed", &JoystickDevice::Mapping::speed)
      .def_readonly("deadband", &JoystickDevice::Mapping::deadband);

  py::class_<JoystickDevice, Device, std::shared_ptr<JoystickDevice>>(
      m, "JoystickDevice",
      "A joystick, gamepad or foot pedal through the Linux joystick interface (/dev/input/jsN): "
      "buttons spin the burr (held), clutch (held) or take the next burr (pressed); axes move "
      "the device. Without a path, events come only from feed().")
      .def(py::init([](const std::string& path, const JoystickDevice::Mapping& mapping) {
             return std::make_shared<JoystickDevice>(path, mapping);
           }),
           py::arg("path") = "", py::arg("mapping") = JoystickDevice::Mapping())
      .def(
          "feed",
          [](JoystickDevice& d, const py::bytes& events) {
            const std::string s = events;
            d.feed(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
          },
          py::arg("events"),
          "Linux js_event records (8 bytes each: uint32 time ms, int16 value, uint8 type, uint8 "
          "number), as read from the device file.")
      .def_property_readonly("mapping", &JoystickDevice::mapping)
      .def_property_readonly("disconnected", &JoystickDevice::disconnected,
                             "the device file failed (unplugged): every button is released");

  py::class_<MergedDevice, Device, std::shared_ptr<MergedDevice>>(
      m, "MergedDevice",
      "A pose from one device and buttons from others (a haptic device with a foot pedal).")
      .def(py::init<std::shared_ptr<Device>, std::vector<std::shared_ptr<Device>>>(),
           py::arg("pose"), py::arg("buttons"));

  py::class_<ReplayDevice, Device, std::shared_ptr<ReplayDevice>>(
      m, "ReplayDevice", "Plays back the readings of an InputDevice's log, step by step.")
      .def(py::init([](const py::dict& log) {
             return std::make_shared<ReplayDevice>(records_from(log));
           }),
           py::arg("log"), "log: {step, position, orientation, buttons} (InputDevice.log).")
      .def_property_readonly("steps_past_end", &ReplayDevice::steps_past_end,
                             "steps read after the last logged one");

  input.def_property_readonly("device", &InputDevice::device)
      .def_property_readonly("drill", [](InputDevice& d) { return handle(d.drill(), d.world()); })
      .def_property_readonly(
          "state", [](InputDevice& d) { return state_dict(d.state()); },
          "the last reading: position (m), orientation (x, y, z, w), buttons")
      .def_property_readonly("clutched", &InputDevice::clutched)
      .def_property_readonly(
          "force", [](InputDevice& d) { return Vec3(d.force()); },
          "the force sent to the device after the last step, N, device frame")
      .def_property_readonly(
          "log", [](InputDevice& d) { return log_arrays(d.log()); },
          "readings since the last take_log(): step, position, orientation, buttons")
      .def(
          "take_log", [](InputDevice& d) { return log_arrays(d.take_log()); },
          "Hands over the readings logged so far and starts a new log.");

  py::class_<StateLock>(m, "_StateLock")
      .def("__enter__",
           [](StateLock& s) {
             py::gil_scoped_release release;
             s.lock = s.world->lock_state();
           })
      .def("__exit__", [](StateLock& s, py::args) {
        if (s.lock.owns_lock()) s.lock.unlock();
        return false;
      });

  py::class_<RealTimeLoop, LoopHolder>(
      m, "RealTimeLoop",
      "Steps a world in real time on its own thread (1 kHz by default, absolute deadlines, "
      "SCHED_FIFO where allowed), while other threads capture. Use as a context manager, or "
      "start()/stop(). Change the world from Python only inside `with loop.lock():`.")
      .def(py::init([](std::shared_ptr<World> world, double rate, int fifo_priority, int cpu,
                       double poll_rate) {
             RealTimeOptions o;
             o.rate = rate;
             o.fifo_priority = fifo_priority;
             o.cpu = cpu;
             o.poll_rate = poll_rate;
             LoopHolder loop(new RealTimeLoop(*world, o));
             World* w = world.get();
             // Python plugins get their physics update on the low-rate thread.
             loop->set_poll_hook([w](double dt) {
               auto lock = w->lock_state();
               if (dt > 0) w->plugins().foreign_physics_update(dt);
             });
             return loop;
           }),
           py::arg("world"), py::arg("rate") = 1000.0, py::arg("fifo_priority") = 80,
           py::arg("cpu") = -1, py::arg("poll_rate") = 100.0, py::keep_alive<1, 2>(),
           "rate: steps per second; fifo_priority: SCHED_FIFO priority to ask for (0: none); "
           "cpu: pin to this CPU (-1: the last, only if SCHED_FIFO is refused; -2: never); "
           "poll_rate: Hz of the thread serving Python devices and plugins.")
      .def(
          "start",
          [](RealTimeLoop& l) {
            py::gil_scoped_release release;
            l.start();
          },
          "Starts stepping.")
      .def(
          "stop",
          [](RealTimeLoop& l) {
            py::gil_scoped_release release;
            l.stop();
          },
          "Stops after the step in progress; re-raises an error that stopped a step.")
      .def_property_readonly("running", &RealTimeLoop::running)
      .def_property_readonly("scheduling", &RealTimeLoop::scheduling,
                             "how the loop's thread is scheduled (SCHED_FIFO, or what it fell "
                             "back to and why)")
      .def_property_readonly(
          "stats", [](RealTimeLoop& l) { return stats_dict(l.stats()); },
          "steps, seconds, mean_rate (Hz), p99 and max period (s), over_2ms (count), "
          "step_cpu_p99 (s), periods (array, s)")
      .def(
          "lock", [](RealTimeLoop& l) { return state_lock(l.world()); },
          "A context manager holding the world's state lock (the loop waits meanwhile).")
      .def(
          "__enter__",
          [](RealTimeLoop& l) -> RealTimeLoop& {
            py::gil_scoped_release release;
            l.start();
            return l;
          },
          py::return_value_policy::reference)
      .def("__exit__", [](RealTimeLoop& l, py::args) {
        py::gil_scoped_release release;
        l.stop();
        return false;
      });
}

}  // namespace ambfplus::bindings
