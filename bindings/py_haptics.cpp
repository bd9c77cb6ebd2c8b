#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <optional>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/simulator.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

RemovalMode parse_mode(const std::string& m) {
  if (m == "physical") return RemovalMode::kPhysical;
  if (m == "compatible") return RemovalMode::kCompatible;
  throw py::value_error("removal must be 'physical' or 'compatible', got '" + m + "'");
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

py::array_t<double> cursor_points(const Drill& d, bool proxies) {
  py::array_t<double> out({py::ssize_t(d.cursor_count()), py::ssize_t(3)});
  auto o = out.mutable_unchecked<2>();
  for (int i = 0; i < d.cursor_count(); ++i) {
    const Vec3 p = proxies ? d.cursor_proxy(i) : d.cursor_goal(i);
    for (int a = 0; a < 3; ++a) o(i, a) = p[a];
  }
  return out;
}

}  // namespace

Drill& add_drill(Model& model, const std::string& name, Volume& volume, const py::kwargs& kw) {
  DrillSpec spec;
  spec.name = name;
  spec.volume = &volume;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "burr_diameters") {
      spec.burr_diameters = v.cast<std::vector<double>>();
    } else if (key == "burr") {
      spec.burr = v.cast<int>();
    } else if (key == "cursors") {
      spec.cursors = v.cast<int>();
    } else if (key == "spacing") {
      spec.spacing = v.cast<double>();
    } else if (key == "shaft_radii") {
      spec.shaft_radii = v.cast<std::vector<double>>();
    } else if (key == "stiffness") {
      spec.stiffness = v.cast<double>();
    } else if (key == "damping") {
      spec.damping = v.cast<double>();
    } else if (key == "max_force") {
      spec.max_force = v.cast<double>();
    } else if (key == "soft_start") {
      spec.soft_start = v.cast<double>();
    } else if (key == "static_friction") {
      spec.friction.static_coefficient = v.cast<double>();
    } else if (key == "dynamic_friction") {
      spec.friction.dynamic_coefficient = v.cast<double>();
    } else if (key == "removal") {
      spec.removal = parse_mode(v.cast<std::string>());
    } else if (key == "cutting_rate") {
      spec.cutting_rate = v.cast<double>();
    } else if (key == "voxels_per_step") {
      spec.voxels_per_step = v.cast<std::vector<int>>();
    } else if (key == "pose") {
      spec.pose = v.cast<Mat4>();
    } else {
      throw py::type_error("add_drill() got an unexpected keyword argument '" + key + "'");
    }
  }
  return model.add_drill(spec);
}

void register_haptics(py::module_& m, py::class_<Drill, Object, std::shared_ptr<Drill>>& drill) {
  drill
      .def_property_readonly("volume",
                             [](Drill& d) {
                               return py::cast(std::shared_ptr<Volume>(
                                   d.world().simulator().shared_from_this(), &d.volume()));
                             })
      .def_property(
          "goal", [](Drill& d) { return Mat4(d.goal().matrix()); },
          [](Drill& d, const Mat4& m) { d.set_goal(checked_pose(m)); },
          "world from drill where the device puts it (burr centre at the origin, shaft along +x)")
      .def_property("on", &Drill::on, &Drill::set_on)
      .def_property("speed", &Drill::speed, &Drill::set_speed, "burr speed, 0..1")
      .def_property("burr", &Drill::burr, &Drill::set_burr, "index into burr_diameters")
      .def_property_readonly("burr_diameters", [](Drill& d) { return d.spec().burr_diameters; })
      .def_property_readonly("burr_radius", &Drill::burr_radius)
      .def_property(
          "removal",
          [](Drill& d) {
            return d.spec().removal == RemovalMode::kPhysical ? "physical" : "compatible";
          },
          [](Drill& d, const std::string& m) { d.set_removal_mode(parse_mode(m)); })
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
            d.attach(body, offset ? checked_pose(*offset) : Eigen::Isometry3d::Identity());
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
            const LabelTable& t = d.volume().data()->label_table();
            for (const auto& [label, dist] : d.critical_distances()) {
              const Label* l = t.find(label);
              out[py::str(l ? l->name : std::to_string(label))] = dist;
            }
            return out;
          },
          "metres from the burr's surface to each critical structure")
      .def_property_readonly(
          "removed", [](Drill& d) { return removed_arrays(d.removed()); },
          "voxels removed and not yet taken: dict of step, voxel (N, 3), label")
      .def("take_removed", [](Drill& d) { return removed_arrays(d.take_removed()); })
      .def_property_readonly("events", [](Drill& d) { return event_list(d.events()); })
      .def("take_events", [](Drill& d) { return event_list(d.take_events()); })
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

  m.def(
      "_benchmark_removal",
      [](Drill& d, int count) {
        // Removes up to `count` voxels nearest the burr through the collider (bitmaps, volume,
        // edit log), as a drilling step does, and times it.
        auto& c = const_cast<VoxelCollider&>(d.collider());
        const Eigen::Isometry3d vfw = d.volume().pose().inverse();
        const Vec3 tip = vfw * d.cursor_proxy(0);
        std::vector<std::array<int, 3>> voxels = c.solid_within(tip, d.burr_radius() * 1.5);
        if (static_cast<int>(voxels.size()) > count) voxels.resize(count);
        double seconds = 0;
        {
          py::gil_scoped_release release;
          const auto t0 = std::chrono::steady_clock::now();
          c.remove(voxels);
          seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        py::dict out;
        out["voxels"] = voxels.size();
        out["seconds"] = seconds;
        return out;
      },
      py::arg("drill"), py::arg("count"));

  m.def(
      "_benchmark_collision",
      [](Drill& d, int cursor, int iterations) {
        // The cursor's last sweep (proxy to goal) as a gather and as a full-cube scan.
        const VoxelCollider& c = d.collider();
        const Eigen::Isometry3d vfw = d.volume().pose().inverse();
        const Vec3 a = vfw * d.cursor_proxy(cursor), b = vfw * d.cursor_goal(cursor);
        const double r = d.cursor_radius(cursor);
        SweepHit gather, full;
        double gather_s = 0, full_s = 0;
        std::int64_t gather_n = 0, full_n = 0;
        {
          py::gil_scoped_release release;
          auto& counter = const_cast<VoxelCollider&>(c);
          counter.reset_counters();
          auto t0 = std::chrono::steady_clock::now();
          for (int i = 0; i < iterations; ++i) gather = c.sweep(a, b, r);
          gather_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                     iterations;
          gather_n = c.voxels_tested() / iterations;
          counter.reset_counters();
          t0 = std::chrono::steady_clock::now();
          for (int i = 0; i < iterations; ++i) full = c.sweep_full_cube(a, b, r);
          full_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                   iterations;
          full_n = c.voxels_tested() / iterations;
        }
        py::dict out;
        out["gather_seconds"] = gather_s;
        out["full_cube_seconds"] = full_s;
        out["gather_voxels"] = gather_n;
        out["full_cube_voxels"] = full_n;
        out["hit"] = gather.hit;
        out["same_hit"] = gather.hit == full.hit && std::abs(gather.t - full.t) < 1e-9;
        return out;
      },
      py::arg("drill"), py::arg("cursor") = 0, py::arg("iterations") = 20);
}

}  // namespace ambfplus::bindings
