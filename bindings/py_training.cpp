#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/world.h"
#include "ambfplus/training/live_metrics.h"
#include "ambfplus/training/skill_metrics.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

/// A number as JSON takes it: infinity (never measured) becomes None.
py::object finite_or_none(double v) {
  return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
}

py::dict structure_dict(const StructureMetrics& s) {
  py::dict d;
  d["name"] = s.name;
  d["margin"] = s.margin;
  d["voxels_removed"] = s.voxels_removed;
  d["contacts"] = s.contacts;
  d["time_in_margin"] = s.time_in_margin;
  d["closest"] = finite_or_none(s.closest);
  d["closest_step"] = s.closest_step;
  d["closest_time"] = s.closest_time;
  d["force_in_margin_mean"] = s.force_in_margin_mean;
  d["force_in_margin_max"] = s.force_in_margin_max;
  d["burr_diameter_in_margin"] = s.burr_diameter_in_margin;
  d["first_breach_step"] = s.first_breach_step;
  d["first_breach_time"] = s.first_breach_time;
  return d;
}

py::dict stroke_dict(const Stroke& s) {
  py::dict d;
  d["first_step"] = s.first_step;
  d["last_step"] = s.last_step;
  d["duration"] = s.duration;
  d["length"] = s.length;
  d["straightness"] = s.straightness;
  d["direction_changes"] = s.direction_changes;
  d["voxels"] = s.voxels;
  return d;
}

py::dict summary_dict(const MetricsSummary& m) {
  py::dict d;
  d["ticks"] = m.ticks;
  d["total_time"] = m.total_time;
  d["burr_on_time"] = m.burr_on_time;
  d["cutting_time"] = m.cutting_time;
  d["voxel_volume"] = m.voxel_volume;
  py::dict by_label;
  for (std::size_t id = 0; id < m.removed_by_label.size(); ++id) {
    if (m.removed_by_label[id]) by_label[py::int_(id)] = m.removed_by_label[id];
  }
  d["removed_by_label"] = by_label;
  d["removed_in_target"] = m.removed_in_target;
  d["removed_outside_target"] = m.removed_outside_target;
  d["cutting_force_mean"] = m.cutting_force_mean;
  d["cutting_force_p95"] = m.cutting_force_p95;
  d["cutting_force_max"] = m.cutting_force_max;
  d["time_above_excess_force"] = m.time_above_excess_force;
  d["efficiency"] = m.efficiency;
  py::list structures, strokes;
  for (const auto& s : m.structures) structures.append(structure_dict(s));
  for (const auto& s : m.strokes) strokes.append(stroke_dict(s));
  d["structures"] = structures;
  d["strokes"] = strokes;
  return d;
}

MetricsConfig config_from(const VolumeData& data, const py::list& protect,
                          const py::handle& target_labels, const py::handle& target_mask,
                          double excess_force, double stroke_gap, double turn_step,
                          double turn_angle, double field_band, bool apply_removals) {
  MetricsConfig c;
  for (const py::handle item : protect) {
    if (!py::isinstance<py::dict>(item)) {
      throw ArgumentTypeError(
          "SkillMetrics: protect takes dicts {'name', 'labels', 'margin'}, got " +
          py::repr(item).cast<std::string>());
    }
    const py::dict entry = py::reinterpret_borrow<py::dict>(item);
    for (const auto& [key, value] : entry) {
      const std::string k = key.cast<std::string>();
      if (k != "name" && k != "labels" && k != "margin") {
        throw ArgumentTypeError("SkillMetrics: protect entry has an unknown key '" + k +
                                "' (known: name, labels, margin)");
      }
    }
    if (!entry.contains("labels")) {
      throw ArgumentError("SkillMetrics: a protect entry names no 'labels'");
    }
    ProtectedStructure s;
    s.labels = structure_labels(data, entry["labels"], "SkillMetrics protect");
    s.name = entry.contains("name") ? entry["name"].cast<std::string>()
                                    : py::str(entry["labels"]).cast<std::string>();
    if (entry.contains("margin")) s.margin = entry["margin"].cast<double>();
    c.protect.push_back(std::move(s));
  }
  if (!target_labels.is_none()) {
    c.target_labels = structure_labels(data, target_labels, "SkillMetrics target_labels");
  }
  if (!target_mask.is_none()) {
    // (I, J, K) like the label grid (VolumeData.labels), stored i fastest.
    const auto mask = py::array_t<std::uint8_t, py::array::forcecast>::ensure(target_mask);
    const auto& n = data.shape();
    if (!mask || mask.ndim() != 3 || mask.shape(0) != n[0] || mask.shape(1) != n[1] ||
        mask.shape(2) != n[2]) {
      throw ArgumentError("SkillMetrics: target_mask must be an array of the volume's shape (" +
                          std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " +
                          std::to_string(n[2]) + ")");
    }
    c.target_mask.resize(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    const auto m = mask.unchecked<3>();
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) c.target_mask[data.linear_index(i, j, k)] = m(i, j, k) != 0;
  }
  c.excess_force = excess_force;
  c.stroke_gap = stroke_gap;
  c.turn_step = turn_step;
  c.turn_angle = turn_angle;
  c.field_band = field_band;
  c.apply_removals = apply_removals;
  return c;
}

using Int32s = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>;
using UInt16s = py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>;
using Int64s = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

void check_rows(const py::array& a, py::ssize_t rows, py::ssize_t width, const char* name) {
  const bool ok = width == 0 ? (a.ndim() == 1 && a.shape(0) == rows)
                             : (a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == width);
  if (!ok) {
    throw ArgumentError(std::string("SkillMetrics.add_ticks: ") + name + " must have " +
                        std::to_string(rows) + " rows" +
                        (width ? " of " + std::to_string(width) : std::string()));
  }
}

}  // namespace

void declare_training(py::module_& m) {
  py::class_<SkillMetrics, std::shared_ptr<SkillMetrics>>(
      m, "SkillMetrics",
      "Skill metrics of a drilling session, fed tick by tick (live) or from a recording "
      "(offline) through the same code.");
  py::class_<LiveMetrics, std::shared_ptr<LiveMetrics>>(
      m, "LiveMetrics",
      "Skill metrics of a drill measured live: its world feeds them at every step, through the "
      "code the offline assessment runs (ambfplus.live_metrics starts them).");
}

void define_training(py::module_& m) {
  bound<SkillMetrics, std::shared_ptr<SkillMetrics>>(m, "SkillMetrics")
      .def(py::init([](const std::shared_ptr<VolumeData>& data, const py::list& protect,
                       const py::handle& target_labels, const py::handle& target_mask,
                       double excess_force, double stroke_gap, double turn_step, double turn_angle,
                       double field_band, bool apply_removals) {
             MetricsConfig c =
                 config_from(*data, protect, target_labels, target_mask, excess_force, stroke_gap,
                             turn_step, turn_angle, field_band, apply_removals);
             py::gil_scoped_release release;
             return std::make_shared<SkillMetrics>(*data, std::move(c));
           }),
           py::arg("volume"), py::kw_only(), py::arg("protect") = py::list(),
           py::arg("target_labels") = py::none(), py::arg("target_mask") = py::none(),
           py::arg("excess_force") = 3.0, py::arg("stroke_gap") = 0.05,
           py::arg("turn_step") = 0.0005, py::arg("turn_angle") = 0.7853981633974483,
           py::arg("field_band") = 0.005, py::arg("apply_removals") = false, py::keep_alive<1, 2>(),
           "Metrics of drilling `volume` (the volume being drilled, which the structures' "
           "distance fields follow). protect: [{'name', 'labels': names or ids, 'margin': "
           "metres}]; target_labels: the labels of the target region, or target_mask: the region "
           "voxel by voxel "
           "(an array of the volume's shape, non-zero inside); excess_force: N; "
           "stroke_gap: s; turn_step: m; turn_angle: rad; field_band: m beyond the margins; "
           "apply_removals: remove each tick's voxels from `volume` (offline, on a fresh copy "
           "of the anatomy).")
      .def(
          "add",
          [](SkillMetrics& s, std::int64_t step, double time, double dt, const Eigen::Vector3d& tip,
             const Eigen::Vector3d& force, double burr_radius, bool burr_on,
             std::optional<Int32s> removed, std::optional<UInt16s> labels) {
            ToolTick t;
            t.step = step;
            t.time = time;
            t.dt = dt;
            t.tip = tip;
            t.force = force;
            t.burr_radius = burr_radius;
            t.burr_on = burr_on;
            if (removed.has_value() != labels.has_value()) {
              throw ArgumentError("SkillMetrics.add: give removed and removed_labels together");
            }
            if (removed) {
              check_rows(*removed, labels->size(), 3, "removed");
              const std::int32_t* v = removed->data();
              for (py::ssize_t r = 0; r < labels->size(); ++r) {
                t.removed.push_back({v[3 * r], v[3 * r + 1], v[3 * r + 2]});
                t.removed_labels.push_back(labels->at(r));
              }
            }
            py::gil_scoped_release release;
            s.add(t);
          },
          py::arg("step"), py::arg("time"), py::arg("dt"), py::arg("tip"), py::arg("force"),
          py::arg("burr_radius"), py::arg("burr_on"), py::arg("removed") = py::none(),
          py::arg("removed_labels") = py::none(),
          "Adds one tick: the burr centre `tip` (volume frame), the force on the hand, and the "
          "voxels removed during it (M, 3) with the labels they had (M,).")
      .def(
          "add_ticks",
          [](SkillMetrics& s, const Int64s& steps, const Doubles& times, double dt,
             const Doubles& tips, const Doubles& forces, const Doubles& radii,
             const py::array_t<bool, py::array::c_style | py::array::forcecast>& on,
             const Int64s& removed_tick, const Int32s& removed, const UInt16s& labels,
             const std::optional<Doubles>& fields_taken) {
            const py::ssize_t n = steps.size();
            // The step log's "<drill>.metrics_fields" of a real-time session: (N, W) bits.
            std::vector<std::vector<int>> takes;
            if (fields_taken) {
              const Doubles& f = *fields_taken;
              if (f.ndim() != 2 || f.shape(0) != n || f.shape(1) < 1) {
                throw ArgumentError("SkillMetrics.add_ticks: fields_taken must have shape (" +
                                    std::to_string(n) + ", W), one row per tick");
              }
              const py::ssize_t w = f.shape(1);
              takes.resize(static_cast<std::size_t>(n));
              for (py::ssize_t i = 0; i < n; ++i) {
                for (py::ssize_t c = 0; c < w; ++c) {
                  const double v = f.data()[i * w + c];
                  if (!(v >= 0.0 && v < 281474976710656.0) || v != std::floor(v)) {
                    throw ArgumentError("SkillMetrics.add_ticks: fields_taken row " +
                                        std::to_string(i) +
                                        " is not a set of 48 bits (an integer 0..2^48-1)");
                  }
                  const auto bits = static_cast<std::uint64_t>(v);
                  for (int b = 0; b < 48; ++b) {
                    if (bits >> b & 1) {
                      takes[static_cast<std::size_t>(i)].push_back(static_cast<int>(c * 48 + b));
                    }
                  }
                }
              }
            }
            check_rows(times, n, 0, "times");
            check_rows(tips, n, 3, "tips");
            check_rows(forces, n, 3, "forces");
            check_rows(radii, n, 0, "burr_radii");
            check_rows(on, n, 0, "burr_on");
            const py::ssize_t m = removed_tick.size();
            check_rows(removed, m, 3, "removed");
            check_rows(labels, m, 0, "removed_labels");
            const std::int64_t* st = steps.data();
            const double* tm = times.data();
            const double* tp = tips.data();
            const double* fo = forces.data();
            const double* ra = radii.data();
            const bool* bo = on.data();
            const std::int64_t* rt = removed_tick.data();
            const std::int32_t* rv = removed.data();
            const std::uint16_t* rl = labels.data();
            // Checked whole before any tick is added, so a bad batch adds nothing.
            for (py::ssize_t r = 0; r < m; ++r) {
              if (rt[r] < 0 || rt[r] >= n || (r > 0 && rt[r] < rt[r - 1])) {
                throw ArgumentError(
                    "SkillMetrics.add_ticks: removed_tick must be sorted indices of the ticks "
                    "given (0.." +
                    std::to_string(n - 1) + "), got " + std::to_string(rt[r]) + " at row " +
                    std::to_string(r));
              }
            }
            py::gil_scoped_release release;
            py::ssize_t r = 0;
            for (py::ssize_t i = 0; i < n; ++i) {
              ToolTick t;
              t.step = st[i];
              t.time = tm[i];
              t.dt = dt;
              t.tip = Eigen::Vector3d(tp[3 * i], tp[3 * i + 1], tp[3 * i + 2]);
              t.force = Eigen::Vector3d(fo[3 * i], fo[3 * i + 1], fo[3 * i + 2]);
              t.burr_radius = ra[i];
              t.burr_on = bo[i];
              for (; r < m && rt[r] == i; ++r) {
                t.removed.push_back({rv[3 * r], rv[3 * r + 1], rv[3 * r + 2]});
                t.removed_labels.push_back(rl[r]);
              }
              if (fields_taken) {
                t.scheduled = true;
                t.take_fields = std::move(takes[static_cast<std::size_t>(i)]);
              }
              s.add(t);
            }
          },
          py::arg("steps"), py::arg("times"), py::arg("dt"), py::arg("tips"), py::arg("forces"),
          py::arg("burr_radii"), py::arg("burr_on"), py::arg("removed_tick"), py::arg("removed"),
          py::arg("removed_labels"), py::arg("fields_taken") = py::none(),
          "Adds N ticks at once (a recording's): steps (N,), times (N,), tips and forces "
          "(N, 3), burr radii and burr on (N,), and the removed voxels (M, 3) with their labels "
          "(M,) and the index of the tick that removed each (M,), sorted. fields_taken: a "
          "real-time session's step-log column '<drill>.metrics_fields' (N, W): the protected "
          "structures' updated fields are taken at those ticks, as live.")
      .def(
          "summary", [](const SkillMetrics& s) { return summary_dict(s.summary()); },
          "Everything measured so far, as a dict (distances in metres, times in seconds, "
          "forces in newtons, volumes as voxel counts with voxel_volume in cubic metres).")
      .def("clearance", &SkillMetrics::clearance, py::arg("structure"), py::arg("point"),
           py::arg("radius"),
           "Distance (metres) from a sphere at `point` (volume frame) to the protected "
           "structure with this index, from its field as of the last tick.");

  bound<LiveMetrics, std::shared_ptr<LiveMetrics>>(m, "LiveMetrics")
      .def(
          "summary",
          [](const LiveMetrics& l) {
            const MetricsSummary summary = [&] {
              py::gil_scoped_release release;
              auto lock = l.drill().world().lock_state_for_copy();
              return l.summary();
            }();
            return summary_dict(summary);
          },
          "The metrics so far, as SkillMetrics.summary() gives them.")
      .def_property_readonly(
          "tick_cpu_seconds",
          [](const LiveMetrics& l) {
            const std::deque<double> t = [&] {
              py::gil_scoped_release release;
              auto lock = l.drill().world().lock_state_for_copy();
              return l.tick_cpu_seconds();
            }();
            return py::array_t<double>(py::ssize_t(t.size()),
                                       std::vector<double>(t.begin(), t.end()).data());
          },
          "CPU seconds the metrics added to each of the last ticks (up to 16384).")
      .def(
          "clearances",
          [](const LiveMetrics& l) {
            const auto all = [&] {
              py::gil_scoped_release release;
              auto lock = l.drill().world().lock_state_for_copy();
              return l.clearances();
            }();
            py::list out;
            for (const auto& c : all) {
              py::dict d;
              d["name"] = c.name;
              d["margin"] = c.margin;
              d["distance"] = finite_or_none(c.distance);
              out.append(d);
            }
            return out;
          },
          "Each protected structure's distance (metres; None once it is gone) from the burr "
          "where it is now, with its margin: [{'name', 'margin', 'distance'}].")
      .def_property_readonly(
          "field_waits",
          [](const LiveMetrics& l) {
            const std::pair<std::int64_t, double> w = [&] {
              py::gil_scoped_release release;
              auto lock = l.drill().world().lock_state_for_copy();
              return std::make_pair(l.metrics().field_waits(), l.metrics().field_wait_seconds());
            }();
            py::dict d;
            d["count"] = w.first;
            d["seconds"] = w.second;
            return d;
          },
          "How often a tick waited for a structure's field brought up to date after a breach "
          "(due kFollowTicks ticks after it, as offline, so that the live metrics equal the "
          "offline assessment), and the seconds waited: {'count', 'seconds'}; zero on a machine "
          "that keeps up.")
      .def_property_readonly("active", &LiveMetrics::active,
                             "Whether the metrics are still fed (their drill is in the world).");

  m.def(
      "burr_in_volume",
      [](const Doubles& world_from_volume, const Doubles& burr_in_world) {
        if (world_from_volume.ndim() != 2 || world_from_volume.shape(0) != 4 ||
            world_from_volume.shape(1) != 4) {
          throw ArgumentError("burr_in_volume: world_from_volume must be a 4x4 matrix");
        }
        if (burr_in_world.ndim() != 2 || burr_in_world.shape(1) != 3) {
          throw ArgumentError("burr_in_volume: burr_in_world must have shape (N, 3)");
        }
        Eigen::Matrix4d pose;
        for (int r = 0; r < 4; ++r) {
          for (int c = 0; c < 4; ++c) pose(r, c) = world_from_volume.at(r, c);
        }
        const py::ssize_t n = burr_in_world.shape(0);
        py::array_t<double> out({n, py::ssize_t(3)});
        auto o = out.mutable_unchecked<2>();
        for (py::ssize_t i = 0; i < n; ++i) {
          const Eigen::Vector3d p(burr_in_world.at(i, 0), burr_in_world.at(i, 1),
                                  burr_in_world.at(i, 2));
          const Eigen::Vector3d v = burr_in_volume(pose, p);
          for (int a = 0; a < 3; ++a) o(i, a) = v[a];
        }
        return out;
      },
      py::arg("world_from_volume"), py::arg("burr_in_world"),
      "The burr centres (N, 3, world) in the frame of the volume at world_from_volume (4x4): the "
      "live metrics' own computation, so that an offline replay sees the same bits.");

  m.def(
      "live_metrics",
      [](Drill& drill, const py::list& protect, const py::handle& target_labels,
         const py::handle& target_mask, double excess_force, double stroke_gap, double turn_step,
         double turn_angle, double field_band) {
        MetricsConfig c =
            config_from(*drill.volume().data(), protect, target_labels, target_mask, excess_force,
                        stroke_gap, turn_step, turn_angle, field_band, false);
        World& world = drill.world();
        LiveMetrics* live = [&] {
          py::gil_scoped_release release;
          return &add_live_metrics(world, drill, std::move(c));
        }();
        return handle(live, world);
      },
      py::arg("drill"), py::kw_only(), py::arg("protect") = py::list(),
      py::arg("target_labels") = py::none(), py::arg("target_mask") = py::none(),
      py::arg("excess_force") = 3.0, py::arg("stroke_gap") = 0.05, py::arg("turn_step") = 0.0005,
      py::arg("turn_angle") = 0.7853981633974483, py::arg("field_band") = 0.005,
      "Starts skill metrics of `drill`, fed by its world after every step (SkillMetrics' "
      "options); its world keeps them until it goes.");
}

}  // namespace ambfplus::bindings
