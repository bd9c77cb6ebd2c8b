// ambfplus/haptics: Drill, the devices (Device and its kinds, JoystickMapping) and InputDevice,
// which binds a device to a drill. Every method of these classes is here.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ambfplus/haptics/device.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"
#include "ambfplus/scene/simulator.h"
#include "bindings.h"
#include "enums.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

// An orientation from Python: None (identity), a quaternion (x, y, z, w) or a 3x3 rotation.
Eigen::Quaterniond to_quaternion(const py::handle& value) {
  if (value.is_none()) return Eigen::Quaterniond::Identity();
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) throw ArgumentTypeError("orientation must be a quaternion (x, y, z, w) or a 3x3 matrix");
  if (a.ndim() == 1 && a.shape(0) == 4) {
    const Eigen::Quaterniond q(a.at(3), a.at(0), a.at(1), a.at(2));
    if (!(q.norm() > 1e-9)) throw ArgumentError("orientation: the quaternion is zero");
    return q.normalized();
  }
  if (a.ndim() == 2 && a.shape(0) == 3 && a.shape(1) == 3) {
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = a.at(i, j);
    if (!(r.transpose() * r).isIdentity(1e-6) || r.determinant() < 0) {
      throw ArgumentError("orientation: the 3x3 matrix is not a rotation");
    }
    return Eigen::Quaterniond(r).normalized();
  }
  throw ArgumentError("orientation must be a quaternion (x, y, z, w) or a 3x3 matrix");
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
        throw ArgumentError(std::string(what) + ": unknown key '" + key +
                            "' (expected position, orientation, buttons)");
      }
    }
    if (!d.contains("position")) throw ArgumentError(std::string(what) + " needs 'position'");
    position = d["position"];
    if (d.contains("orientation")) orientation = d["orientation"];
    if (d.contains("buttons")) buttons = d["buttons"];
  } else if (py::isinstance<py::tuple>(value) || py::isinstance<py::list>(value)) {
    auto t = py::reinterpret_borrow<py::sequence>(value);
    if (py::len(t) < 1 || py::len(t) > 3) {
      throw ArgumentError(std::string(what) + ": expected (position[, orientation[, buttons]])");
    }
    position = t[0];
    if (py::len(t) > 1) orientation = t[1];
    if (py::len(t) > 2) buttons = t[2];
  } else {
    throw ArgumentTypeError(std::string(what) +
                            " must be a dict {position, orientation, buttons} or a tuple "
                            "(position[, orientation[, buttons]]), got " +
                            std::string(py::repr(value)).substr(0, 80));
  }
  // Wrong types (text for a position) are ambfplus errors naming what was given and expected.
  auto got = [](const py::handle& v) { return std::string(py::repr(v)).substr(0, 80); };
  try {
    s.position = position.cast<Vec3>();
  } catch (const py::cast_error&) {
    throw ArgumentTypeError(std::string(what) + ": position must be 3 numbers (x, y, z), got " +
                            got(position));
  }
  if (!s.position.allFinite()) throw ArgumentError(std::string(what) + ": position not finite");
  try {
    s.orientation = to_quaternion(orientation);
  } catch (const ArgumentTypeError& e) {
    throw ArgumentTypeError(std::string(what) + ": " + e.what() + ", got " + got(orientation));
  } catch (const ArgumentError& e) {
    throw ArgumentError(std::string(what) + ": " + e.what());
  }
  if (!py::isinstance<py::int_>(buttons) || py::isinstance<py::bool_>(buttons)) {
    throw ArgumentTypeError(std::string(what) +
                            ": buttons must be an integer (a bit per button), got " + got(buttons));
  }
  const long long b = buttons.cast<long long>();
  if (b < 0 || b > 0xffffffffLL) throw ArgumentError(std::string(what) + ": buttons out of range");
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
      throw ArgumentError(std::string("a device log needs '") + key +
                          "' (as InputDevice.log gives it)");
    }
  }
  auto step = py::array_t<std::int64_t, py::array::forcecast>::ensure(log["step"]);
  auto position = py::array_t<double, py::array::forcecast>::ensure(log["position"]);
  auto orientation = py::array_t<double, py::array::forcecast>::ensure(log["orientation"]);
  auto buttons = py::array_t<std::int64_t, py::array::forcecast>::ensure(log["buttons"]);
  if (!step || !position || !orientation || !buttons || step.ndim() != 1) {
    throw ArgumentError("a device log's entries must be numeric arrays");
  }
  const py::ssize_t n = step.shape(0);
  if (position.ndim() != 2 || position.shape(0) != n || position.shape(1) != 3 ||
      orientation.ndim() != 2 || orientation.shape(0) != n || orientation.shape(1) != 4 ||
      buttons.ndim() != 1 || buttons.shape(0) != n) {
    throw ArgumentError(
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

py::dict removed_arrays(const std::deque<RemovedVoxel>& removed) {
  const auto n = static_cast<py::ssize_t>(removed.size());
  py::array_t<std::int64_t> step(n);
  py::array_t<std::int32_t> voxel({n, py::ssize_t(3)});
  py::array_t<std::uint16_t> label(n);
  auto s = step.mutable_unchecked<1>();
  auto v = voxel.mutable_unchecked<2>();
  auto l = label.mutable_unchecked<1>();
  py::ssize_t i = 0;
  for (const RemovedVoxel& r : removed) {
    s(i) = r.step;
    for (int a = 0; a < 3; ++a) v(i, a) = r.voxel[a];
    l(i) = r.label;
    ++i;
  }
  py::dict d;
  d["step"] = step;
  d["voxel"] = voxel;
  d["label"] = label;
  return d;
}

py::list event_list(const std::deque<DrillEvent>& events) {
  py::list out;
  for (const DrillEvent& e : events) {
    py::dict d;
    d["step"] = e.step;
    d["kind"] = e.kind;
    d["label"] = e.label;
    d["voxel"] = py::make_tuple(e.voxel[0], e.voxel[1], e.voxel[2]);
    out.append(d);
  }
  return out;
}

// What f returns, called with the GIL released (f takes the world's lock: Python never runs
// under it, and other Python threads run while this one waits for it).
template <typename F>
auto without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

// What f returns, called under the drill's world's lock with the GIL released: the drill's
// containers change at every step of a real-time loop, so they are copied under the lock, and
// Python objects are made from the copy after it.
template <typename F>
auto locked_copy(const Drill& d, F&& f) {
  return without_gil([&] {
    auto lock = d.world().lock_state_for_copy();
    return f();
  });
}

}  // namespace

std::vector<std::pair<std::string, double>> critical_distances_by_name(const Drill& drill) {
  const LabelTable& table = drill.volume().data()->label_table();
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [label, distance] : drill.critical_distances()) {
    const Label* l = table.find(label);
    out.emplace_back(l ? l->name : std::to_string(label), distance);
  }
  return out;
}

namespace {

py::array_t<double> cursor_points(const Drill& d, bool proxies) {
  const std::vector<Vec3> points = locked_copy(d, [&] {
    std::vector<Vec3> p;
    for (int i = 0; i < d.cursor_count(); ++i)
      p.push_back(proxies ? d.cursor_proxy(i) : d.cursor_goal(i));
    return p;
  });
  py::array_t<double> out({py::ssize_t(points.size()), py::ssize_t(3)});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int a = 0; a < 3; ++a) o(py::ssize_t(i), a) = points[i][a];
  }
  return out;
}

void define_devices(py::module_& m) {
  bound<Device, std::shared_ptr<Device>>(m, "Device")
      .def_property_readonly(
          "spec", [](Device& d) { return spec_dict(d.spec()); },
          "name, max_force (N), max_stiffness (N/m), max_damping (N s/m), workspace_radius (m)")
      .def_property_readonly(
          "last_force", [](Device& d) { return Vec3(d.last_force()); },
          "the force last sent to it, N, device frame");

  bound<NullDevice, Device, std::shared_ptr<NullDevice>>(m, "NullDevice").def(py::init<>());

  bound<SimulatedDevice, Device, std::shared_ptr<SimulatedDevice>>(m, "SimulatedDevice")
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

  bound<ScriptedDevice, Device, std::shared_ptr<ScriptedDevice>>(m, "ScriptedDevice")
      .def(py::init<>())
      .def(
          "set_waypoints",
          [](ScriptedDevice& d, const py::list& waypoints) {
            std::vector<ScriptedDevice::Waypoint> w;
            for (const py::handle& item : waypoints) {
              if (!py::isinstance<py::dict>(item) || !item.cast<py::dict>().contains("time")) {
                throw ArgumentError("a waypoint is a dict {time, position, orientation, buttons}");
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
            const std::string what =
                "the device callback's result (callback " +
                std::string(py::str(py::getattr(callback, "__qualname__", py::repr(callback)))) +
                ")";
            // Holds the callable through a shared_ptr whose deleter takes the GIL, since the
            // sampler may be destroyed on a thread without it.
            auto fn = std::shared_ptr<py::function>(new py::function(std::move(callback)),
                                                    [](py::function* f) {
                                                      py::gil_scoped_acquire gil;
                                                      delete f;
                                                    });
            d.set_sampler(
                [fn, what](double time) {
                  py::gil_scoped_acquire gil;
                  return to_state((*fn)(time), what.c_str());
                },
                every);
          },
          py::arg("callback"), py::arg("every") = 10,
          "callback(time) -> {position, orientation, buttons} or (position[, orientation[, "
          "buttons]]), called every `every` steps (in a real-time loop from its low-rate "
          "thread); the reading is held in between.");

  bound<KeyboardDevice, Device, std::shared_ptr<KeyboardDevice>>(m, "KeyboardDevice")
      .def(py::init<double, double>(), py::arg("step") = 0.001,
           py::arg("angle") = 0.05235987755982988)
      .def("key", &KeyboardDevice::key, py::arg("key"), py::arg("action"), py::arg("mods"),
           "A key event (GLFW key code, action 0 release / 1 press / 2 repeat, modifier bits); "
           "True when it is one of the device's keys.")
      .def(
          "set_state",
          [](KeyboardDevice& d, const py::object& state) { d.set_state(to_state(state, "state")); },
          py::arg("state"), "Sets the reading ({position, orientation, buttons}).");

  bound<NetworkDevice, Device, std::shared_ptr<NetworkDevice>>(m, "NetworkDevice")
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

  bound<JoystickDevice::Mapping>(m, "JoystickMapping")
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

  bound<JoystickDevice, Device, std::shared_ptr<JoystickDevice>>(m, "JoystickDevice")
      .def(py::init([](const std::string& path, const JoystickDevice::Mapping& mapping) {
             return std::make_shared<JoystickDevice>(path, mapping);
           }),
           py::arg("path") = "",
           py::arg_v("mapping", JoystickDevice::Mapping(), "JoystickMapping()"))
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

  bound<MergedDevice, Device, std::shared_ptr<MergedDevice>>(m, "MergedDevice")
      .def(py::init<std::shared_ptr<Device>, std::vector<std::shared_ptr<Device>>>(),
           py::arg("pose"), py::arg("buttons"));

  bound<ReplayDevice, Device, std::shared_ptr<ReplayDevice>>(m, "ReplayDevice")
      .def(py::init([](const py::dict& log) {
             return std::make_shared<ReplayDevice>(records_from(log));
           }),
           py::arg("log"), "log: {step, position, orientation, buttons} (InputDevice.log).")
      .def_property_readonly("steps_past_end", &ReplayDevice::steps_past_end,
                             "steps read after the last logged one");
}

void define_input_device(py::module_& m) {
  bound<InputDevice, Object, std::shared_ptr<InputDevice>>(m, "InputDevice")
      .def_property_readonly("device", &InputDevice::device)
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
          "Hands over the readings logged so far and starts a new log.")
      .def_property_readonly("log_dropped", &InputDevice::log_dropped,
                             "readings dropped because nobody took them in time (the newest "
                             "InputDevice.MAX_LOG are kept)")
      .def_readonly_static("MAX_LOG", &InputDevice::kMaxLog,
                           "readings kept until taken (take_log)");
}

void define_drill(py::module_& m) {
  bound<Drill, Object, std::shared_ptr<Drill>>(m, "Drill")
      .def_property_readonly("volume",
                             [](Drill& d) {
                               return py::cast(std::shared_ptr<Volume>(
                                   d.world().simulator().shared_from_this(), &d.volume()));
                             })
      .def_property(
          "pose", [](Drill& d) { return Mat4(d.pose().matrix()); },
          [](Drill& d, const Mat4& m) { d.place(checked_pose(m, d)); },
          "4x4 world from drill (a copy); assigning places the drill there at once, goal and "
          "cursors too, as at its creation (assign goal to move it there through the tissue)")
      .def_property(
          "goal", [](Drill& d) { return Mat4(d.goal().matrix()); },
          [](Drill& d, const Mat4& m) { d.set_goal(checked_pose(m, d, "goal")); },
          "world from drill where the device puts it (burr centre at the origin, shaft along +x)")
      .def_property("on", &Drill::on, &Drill::set_on)
      .def_property("speed", &Drill::speed, &Drill::set_speed, "burr speed, 0..1")
      .def_property("burr", &Drill::burr, &Drill::set_burr, "index into burr_diameters")
      .def_property_readonly("burr_diameters", [](Drill& d) { return d.spec().burr_diameters; })
      .def_property_readonly("burr_radius", &Drill::burr_radius)
      .def_property(
          "removal", [](Drill& d) { return removal_mode_name(d.spec().removal); },
          [](Drill& d, const KindOrName<RemovalMode>& mode) {
            d.set_removal_mode(to_kind(mode, &parse_removal_mode, "RemovalMode"));
          },
          "physical or compatible")
      .def_property(
          "stiffness", [](Drill& d) { return d.spec().stiffness; }, &Drill::set_stiffness)
      .def_property(
          "cutting_rate", [](Drill& d) { return d.spec().cutting_rate; }, &Drill::set_cutting_rate,
          "m^3 per second per newton at full speed")
      .def("set_hardness", &Drill::set_hardness, py::arg("label"), py::arg("hardness"))
      .def(
          "set_waypoints",
          [](Drill& d, const py::list& points) {
            std::vector<DrillWaypoint> w;
            for (const py::handle& p : points) {
              const py::dict e = p.cast<py::dict>();
              DrillWaypoint wp;
              wp.time = e["time"].cast<double>();
              wp.pose = e["pose"].cast<Mat4>();
              if (e.contains("on")) wp.on = e["on"].cast<bool>();
              if (e.contains("speed")) wp.speed = e["speed"].cast<double>();
              w.push_back(wp);
            }
            d.set_waypoints(w);
          },
          py::arg("waypoints"),
          "follow dicts of time (s from now), pose (4x4) and optionally on and speed, "
          "interpolating between them")
      .def(
          "attach",
          [](Drill& d, RigidBody& body, std::optional<Mat4> offset) {
            d.attach(body, offset ? checked_pose(*offset, d, "attach offset")
                                  : Eigen::Isometry3d::Identity());
          },
          py::arg("body"), py::arg("offset") = py::none(), "move body with the drill")
      .def_property_readonly(
          "force", [](Drill& d) { return Vec3(d.force()); },
          "force fed back (the leading cursor's), N, world frame")
      .def_property_readonly("total_force", [](Drill& d) { return Vec3(d.total_force()); })
      .def_property_readonly("leading_cursor", &Drill::leading_cursor)
      .def_property_readonly("cursor_proxies", [](Drill& d) { return cursor_points(d, true); })
      .def_property_readonly("cursor_goals", [](Drill& d) { return cursor_points(d, false); })
      .def_property_readonly("cursor_radii",
                             [](Drill& d) {
                               std::vector<double> r;
                               for (int i = 0; i < d.cursor_count(); ++i)
                                 r.push_back(d.cursor_radius(i));
                               return r;
                             })
      .def_property_readonly("cursor_contacts",
                             [](Drill& d) {
                               std::vector<int> c;
                               for (int i = 0; i < d.cursor_count(); ++i)
                                 c.push_back(d.cursor_contacts(i));
                               return c;
                             })
      .def_property_readonly("tip_normal", &Drill::tip_normal)
      .def_property_readonly(
          "critical_distances",
          [](Drill& d) {
            py::dict out;
            for (const auto& [name, distance] :
                 locked_copy(d, [&] { return critical_distances_by_name(d); })) {
              out[py::str(name)] = distance;
            }
            return out;
          },
          "metres from the burr's surface to each critical structure")
      .def(
          "set_fixture",
          [](Drill& d, const py::object& structure, double start, double max_force,
             std::optional<double> stop, bool enabled) {
            FixtureSpec f;
            f.structure = to_option(structure).type() == OptionValue::Type::kInteger
                              ? std::to_string(structure.cast<long long>())
                              : structure.cast<std::string>();
            f.start = start;
            f.max_force = max_force;
            f.stop = stop.value_or(0.0);
            f.enabled = enabled;
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.set_fixture(f);
            });
          },
          py::arg("structure"), py::kw_only(), py::arg("start"), py::arg("max_force") = 1.0,
          py::arg("stop") = py::none(), py::arg("enabled") = true,
          "sets the forbidden-region fixture of a structure (label name or id), replacing its "
          "last: below `start` metres from the burr's surface a force up to `max_force` N at "
          "the structure pushes the burr away; below `stop` metres (None: no hard stop) nothing "
          "is cut and the burr is held back")
      .def(
          "set_fixtures",
          [](Drill& d, const py::list& fixtures) {
            std::vector<FixtureSpec> all;
            for (std::size_t i = 0; i < fixtures.size(); ++i) {
              all.push_back(fixture_from(OptionValue::mapping(to_options(fixtures[i])),
                                         "fixtures[" + std::to_string(i) + "]"));
            }
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.set_fixtures(all);
            });
          },
          py::arg("fixtures"),
          "replaces every fixture by a list of dicts (a DRILL block's `fixtures`): structure, "
          "start, max_force (default 1 N), stop (default None), enabled (default True); [] "
          "removes them")
      .def_property_readonly(
          "fixtures",
          [](Drill& d) {
            py::list out;
            for (const FixtureSpec& f : locked_copy(d, [&] { return d.fixtures(); })) {
              py::dict e;
              e["structure"] = f.structure;
              e["start"] = f.start;
              e["max_force"] = f.max_force;
              e["stop"] = f.stop > 0 ? py::object(py::float_(f.stop)) : py::object(py::none());
              e["enabled"] = f.enabled;
              out.append(e);
            }
            return out;
          },
          "the fixtures as dicts (set_fixtures' form), structures by label name")
      .def(
          "set_plan",
          [](Drill& d, const py::object& target, double start, double max_force,
             std::optional<double> stop, bool enabled) {
            FixtureSpec f;
            f.start = start;
            f.max_force = max_force;
            f.stop = stop.value_or(0.0);
            f.enabled = enabled;
            if (py::isinstance<py::array>(target)) {
              // (nx, ny, nz), i fastest: Fortran order, as VolumeData.labels.
              auto a = py::array_t<std::uint8_t, py::array::f_style | py::array::forcecast>::ensure(
                  target);
              const auto& n = d.volume().data()->shape();
              if (!a || a.ndim() != 3 || a.shape(0) != n[0] || a.shape(1) != n[1] ||
                  a.shape(2) != n[2]) {
                throw ArgumentError("set_plan: a mask must have the volume's shape (" +
                                    std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " +
                                    std::to_string(n[2]) + ")");
              }
              std::vector<std::uint8_t> mask(a.data(), a.data() + a.size());
              without_gil([&] {
                auto lock = d.world().lock_state_for_copy();
                d.set_plan(mask, f);
              });
              return;
            }
            std::vector<std::string> labels;
            for (const py::handle& h : target) {
              labels.push_back(py::isinstance<py::int_>(h) ? std::to_string(h.cast<long long>())
                                                           : h.cast<std::string>());
            }
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.set_plan(labels, f);
            });
          },
          py::arg("target"), py::kw_only(), py::arg("start"), py::arg("max_force") = 1.0,
          py::arg("stop") = py::none(), py::arg("enabled") = true,
          "stay in the plan: a fixture on the boundary of a planned region, `target` a boolean "
          "mask of the volume's shape (nx, ny, nz) or a list of labels (names or ids); every "
          "labelled voxel outside it is the forbidden side (with a `stop`, nothing outside it "
          "is cut)")
      .def(
          "clear_plan",
          [](Drill& d) {
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.clear_plan();
            });
          },
          "removes the plan's fixture (and its attraction, follow_plan)")
      .def(
          "set_plan_enabled",
          [](Drill& d, bool enabled) {
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.set_plan_enabled(enabled);
            });
          },
          py::arg("enabled"),
          "turns the plan's fixture off or back on, its field kept (set_plan rebuilds it)")
      .def(
          "follow_plan",
          [](Drill& d, double max_force, double start, bool enabled) {
            without_gil([&] {
              auto lock = d.world().lock_state_for_copy();
              d.follow_plan(max_force, start, enabled);
            });
          },
          py::kw_only(), py::arg("max_force") = 0.5, py::arg("start") = 0.002,
          py::arg("enabled") = true,
          "follow the plan: draws the burr toward the nearest voxel of the plan not yet removed, "
          "max_force x min(1, d / start) N for a burr surface d metres from it, fading to zero "
          "between 2 x start and 3 x start, none once touching; part of fixture_force, kept "
          "passive. Needs a plan (set_plan); clear_plan ends it")
      .def_property_readonly(
          "follows_plan",
          [](Drill& d) -> py::object {
            if (!d.follows_plan()) return py::none();
            py::dict e;
            e["max_force"] = d.follow_max_force();
            e["start"] = d.follow_start();
            return e;
          },
          "the plan's attraction as {max_force, start}, or None when off")
      .def_property_readonly(
          "plan",
          [](Drill& d) -> py::object {
            const FixtureSpec* f = d.plan();
            if (f == nullptr) return py::none();
            py::dict e;
            e["start"] = f->start;
            e["max_force"] = f->max_force;
            e["stop"] = f->stop > 0 ? py::object(py::float_(f->stop)) : py::object(py::none());
            e["enabled"] = f->enabled;
            e["voxels"] = d.plan_voxels();
            return std::move(e);
          },
          "the plan's fixture as a dict (start, max_force, stop, enabled, voxels), or None")
      .def_property_readonly(
          "fixture_force", [](Drill& d) { return Vec3(d.fixture_force()); },
          "the part of `force` the fixtures added at the last step, N, world frame")
      .def_property("fixture_passivity", &Drill::fixture_passivity, &Drill::set_fixture_passivity,
                    "keep the fixtures' force passive (energy observer and damping; default on)")
      .def_property_readonly(
          "removed",
          [](Drill& d) { return removed_arrays(locked_copy(d, [&] { return d.removed(); })); },
          "voxels removed and not yet taken: dict of step, voxel (N, 3), label (a copy made "
          "under the world's lock; take_removed() takes them without copying)")
      .def(
          "take_removed",
          [](Drill& d) { return removed_arrays(without_gil([&] { return d.take_removed(); })); },
          "the voxels removed since the last take, handed over (the drill keeps none)")
      .def_property_readonly(
          "events", [](Drill& d) { return event_list(locked_copy(d, [&] { return d.events(); })); })
      .def("take_events",
           [](Drill& d) { return event_list(without_gil([&] { return d.take_events(); })); })
      .def_property_readonly("removed_dropped", &Drill::removed_dropped,
                             "removed voxels dropped because nobody took them in time (the newest "
                             "Drill.MAX_REMOVED are kept)")
      .def_property_readonly(
          "events_dropped", &Drill::events_dropped,
          "events dropped because nobody took them in time (the newest Drill.MAX_EVENTS are kept)")
      .def_readonly_static("MAX_REMOVED", &Drill::kMaxRemoved,
                           "removed voxels kept until taken (take_removed)")
      .def_readonly_static("MAX_EVENTS", &Drill::kMaxEvents,
                           "events kept until taken (take_events)")
      .def_property_readonly(
          "tick_seconds",
          [](Drill& d) {
            const auto& t = d.tick_seconds();
            return py::array_t<double>(py::ssize_t(t.size()),
                                       std::vector<double>(t.begin(), t.end()).data());
          },
          "wall time of recent ticks, seconds")
      .def_property_readonly(
          "tick_cpu_seconds",
          [](Drill& d) {
            const auto& t = d.tick_cpu_seconds();
            return py::array_t<double>(py::ssize_t(t.size()),
                                       std::vector<double>(t.begin(), t.end()).data());
          },
          "thread CPU time of the same ticks, seconds");
}

}  // namespace

void declare_haptics(py::module_& m) {
  declare_enum<RemovalMode>(
      m, "RemovalMode", "How a drill's burr removes tissue.",
      {{"physical", RemovalMode::kPhysical}, {"compatible", RemovalMode::kCompatible}},
      &parse_removal_mode);
  py::class_<Drill, Object, std::shared_ptr<Drill>>(
      m, "Drill", "A burr and shaft of finger-proxy cursors that drills a volume.");
  py::class_<Device, std::shared_ptr<Device>>(
      m, "Device",
      "A haptic or input device, read once per world step and sent the force to render.");
  py::class_<NullDevice, Device, std::shared_ptr<NullDevice>>(
      m, "NullDevice", "No device: at the origin, no buttons, forces ignored.");
  py::class_<SimulatedDevice, Device, std::shared_ptr<SimulatedDevice>>(
      m, "SimulatedDevice",
      "A hand holding a device, simulated: a mass pulled to a target by a spring and damper and "
      "pushed by the rendered force, so contact stops it. Deterministic.");
  py::class_<ScriptedDevice, Device, std::shared_ptr<ScriptedDevice>>(
      m, "ScriptedDevice",
      "A device following waypoints, or a Python callback sampled every `every` steps.");
  py::class_<KeyboardDevice, Device, std::shared_ptr<KeyboardDevice>>(
      m, "KeyboardDevice",
      "The keyboard as a device, with the original drilling simulator's bindings: Ctrl+W/S/D/A/"
      "I/K move by `step` (up, down, right, left, into and out of the screen of the reference "
      "camera), keypad 8/5 and 4/6 turn by `angle`, Space toggles the burr (button 0), C takes "
      "the next burr (button 2).");
  py::class_<NetworkDevice, Device, std::shared_ptr<NetworkDevice>>(
      m, "NetworkDevice",
      "A device on the network: a bridge sends 80-byte UDP pose datagrams and gets 48-byte "
      "force datagrams back after every step (format in ambfplus/haptics/device.h and "
      "README); bound to loopback unless another address is given. Malformed, oversized or "
      "stale messages are rejected and counted.");
  py::class_<JoystickDevice::Mapping>(m, "JoystickMapping",
                                      "Which joystick buttons and axes do what.");
  py::class_<JoystickDevice, Device, std::shared_ptr<JoystickDevice>>(
      m, "JoystickDevice",
      "A joystick, gamepad or foot pedal through the Linux joystick interface (/dev/input/jsN): "
      "buttons spin the burr (held), clutch (held) or take the next burr (pressed); axes move "
      "the device. Without a path, events come only from feed().");
  py::class_<MergedDevice, Device, std::shared_ptr<MergedDevice>>(
      m, "MergedDevice",
      "A pose from one device and buttons from others (a haptic device with a foot pedal).");
  py::class_<ReplayDevice, Device, std::shared_ptr<ReplayDevice>>(
      m, "ReplayDevice", "Plays back the readings of an InputDevice's log, step by step.");
  py::class_<InputDevice, Object, std::shared_ptr<InputDevice>>(
      m, "InputDevice",
      "A device bound to a drill: its motion moves the drill's goal (workspace scale, clutch, "
      "the reference's axes), its buttons turn and change the burr, the drill's force goes back; "
      "every reading is logged with its step.");
}

void define_haptics(py::module_& m) {
  define_devices(m);
  define_input_device(m);
  define_drill(m);
}

}  // namespace ambfplus::bindings
