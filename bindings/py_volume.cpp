// ambfplus/volume: Label, VolumeData (its grids as views with the data as owner), the volume
// readers and writers, the phantom.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <optional>
#include <sstream>

#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/errors.h"
#include "ambfplus/render/render_stats.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/volume/distance_field.h"
#include "ambfplus/volume/phantom.h"
#include "ambfplus/volume/volume_io.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;

// A Fortran-order (i fastest) NumPy view of a grid owned by the VolumeData behind `owner`.
py::array grid_view(py::object owner, const VolumeData& v, void* data, py::dtype dtype,
                    bool writeable) {
  const auto& n = v.shape();
  const auto size = static_cast<py::ssize_t>(dtype.itemsize());
  py::array a(dtype, {py::ssize_t(n[0]), py::ssize_t(n[1]), py::ssize_t(n[2])},
              {size, size * n[0], size * n[0] * n[1]}, data, owner);
  return writeable ? a : readonly(a);
}

py::dtype label_dtype(LabelType t) {
  return t == LabelType::kUInt8 ? py::dtype::of<std::uint8_t>() : py::dtype::of<std::uint16_t>();
}

py::tuple box_tuple(const VoxelBox& b) {
  return py::make_tuple(py::make_tuple(b.lo[0], b.lo[1], b.lo[2]),
                        py::make_tuple(b.hi[0], b.hi[1], b.hi[2]));
}

py::object edit_dict(const VolumeEdit& e) {
  py::dict d;
  d["revision"] = e.revision;
  d["kind"] = e.kind;
  d["box"] = box_tuple(e.box);
  d["changed"] = e.changed;
  py::array_t<std::int32_t> voxels({py::ssize_t(e.voxels.size()), py::ssize_t(3)});
  auto v = voxels.mutable_unchecked<2>();
  for (std::size_t i = 0; i < e.voxels.size(); ++i) {
    for (int a = 0; a < 3; ++a) v(py::ssize_t(i), a) = e.voxels[i][a];
  }
  d["voxels"] = voxels;
  d["old_labels"] =
      py::array_t<std::uint16_t>(py::ssize_t(e.old_labels.size()), e.old_labels.data());
  return d;
}

LabelTable table_from(const py::object& labels) {
  if (labels.is_none()) return LabelTable();
  if (py::isinstance<py::str>(labels) || py::hasattr(labels, "__fspath__")) {
    return read_label_table(py::module_::import("os").attr("fspath")(labels).cast<std::string>());
  }
  return LabelTable(labels.cast<std::vector<Label>>());
}

std::shared_ptr<VolumeData> from_array(py::array labels, std::optional<Vec3> dimensions,
                                       std::optional<Vec3> voxel_size, const py::object& table) {
  if (labels.ndim() != 3) throw ArgumentError("labels must be a 3D array (nx, ny, nz)");
  const bool u8 = labels.dtype().is(py::dtype::of<std::uint8_t>());
  const bool u16 = labels.dtype().is(py::dtype::of<std::uint16_t>());
  if (!u8 && !u16) {
    throw ArgumentTypeError("labels must be uint8 or uint16, got " +
                            py::str(labels.dtype()).cast<std::string>());
  }
  const std::array<int, 3> shape = {int(labels.shape(0)), int(labels.shape(1)),
                                    int(labels.shape(2))};
  Vec3 dims;
  if (dimensions && voxel_size) throw ArgumentError("give dimensions or voxel_size, not both");
  if (dimensions) {
    check_volume_sizes(*dimensions, "VolumeData: dimensions");
    dims = *dimensions;
  } else if (voxel_size) {
    check_volume_sizes(*voxel_size, "VolumeData: voxel_size");
    dims = voxel_size->cwiseProduct(Vec3(shape[0], shape[1], shape[2]));
  } else {
    throw ArgumentError("give the volume's size: dimensions=(x, y, z) metres or voxel_size=");
  }
  LabelTable t = table_from(table);
  const LabelType type = u8 ? LabelType::kUInt8 : LabelType::kUInt16;
  auto v = std::make_shared<VolumeData>(shape, dims, type, t);
  // Copy in, i fastest, whatever the array's own layout.
  py::array f = py::module_::import("numpy").attr("asfortranarray")(labels);
  std::memcpy(v->label_data(), f.data(), static_cast<std::size_t>(v->voxel_count()) * f.itemsize());
  if (t.empty()) {
    // Name the ids present.
    const auto counts = v->label_counts();
    for (std::size_t id = 1; id < counts.size(); ++id) {
      if (counts[id] > 0)
        t.add(
            Label{std::uint16_t(id), "label_" + std::to_string(id), {200, 200, 200}, true, false});
    }
    v->set_label_table(t);
  }
  v->commit();
  return v;
}

}  // namespace

VoxelBox box_from(std::optional<std::array<int, 3>> lo, std::optional<std::array<int, 3>> hi,
                  const VolumeData& v) {
  VoxelBox b{{0, 0, 0}, v.shape()};
  if (lo) b.lo = *lo;
  if (hi) b.hi = *hi;
  return b;
}

py::object hit_dict(const VolumeHit& h) {
  if (!h.hit) return py::none();
  py::dict d;
  d["distance"] = h.t;
  d["position"] = h.position;
  d["normal"] = h.normal;
  d["label"] = h.label;
  d["voxel"] = h.voxel;
  return d;
}

void declare_volume(py::module_& m) {
  py::class_<Label>(m, "Label", "One structure of a segmented volume (id 0 means no label).");
  py::class_<VolumeData, std::shared_ptr<VolumeData>>(
      m, "VolumeData",
      "A segmented volume: label grid (a view, indexed [i, j, k]), label table, size, edits.");
  py::class_<DistanceField, std::shared_ptr<DistanceField>>(
      m, "DistanceField",
      "The exact signed distance (metres) from every voxel centre of a volume to a structure, "
      "clamped to a band; brought up to date by update() as the volume is edited.");
}

std::vector<std::uint16_t> structure_labels(const VolumeData& data, const py::handle& labels,
                                            const std::string& what) {
  std::vector<std::uint16_t> ids;
  auto add = [&](const py::handle& item) {
    const std::string name = py::isinstance<py::str>(item) ? item.cast<std::string>()
                                                           : std::to_string(item.cast<long long>());
    ids.push_back(resolve_label(data.label_table(), name, what));
  };
  if (py::isinstance<py::str>(labels) || py::isinstance<py::int_>(labels)) {
    add(labels);
  } else {
    for (const py::handle item : labels) add(item);
  }
  return ids;
}

void define_volume(py::module_& m) {
  bound<Label>(m, "Label")
      .def(py::init([](int id, std::string name, std::array<int, 3> color, bool removable,
                       bool critical) {
             if (id < 1 || id > 65535) throw ArgumentError("label id must be in 1..65535");
             Label l;
             l.id = static_cast<std::uint16_t>(id);
             l.name = std::move(name);
             for (int c = 0; c < 3; ++c) {
               if (color[c] < 0 || color[c] > 255) throw ArgumentError("color must be 0..255");
               l.color[c] = static_cast<std::uint8_t>(color[c]);
             }
             l.removable = removable;
             l.critical = critical;
             return l;
           }),
           py::arg("id"), py::arg("name"), py::arg("color") = std::array<int, 3>{255, 255, 255},
           py::arg("removable") = true, py::arg("critical") = false)
      .def_readonly("id", &Label::id)
      .def_readonly("name", &Label::name)
      .def_property_readonly(
          "color",
          [](const Label& l) { return py::make_tuple(l.color[0], l.color[1], l.color[2]); })
      .def_readonly("removable", &Label::removable)
      .def_readonly("critical", &Label::critical)
      .def("__eq__",
           [](const Label& a, const Label& b) {
             return a.id == b.id && a.name == b.name && a.color == b.color &&
                    a.removable == b.removable && a.critical == b.critical;
           })
      .def("__repr__", [](const Label& l) {
        std::ostringstream s;
        s << "Label(" << l.id << ", '" << l.name << "', color=(" << int(l.color[0]) << ", "
          << int(l.color[1]) << ", " << int(l.color[2]) << ")"
          << (l.removable ? "" : ", removable=False") << (l.critical ? ", critical=True" : "")
          << ")";
        return s.str();
      });

  bound<VolumeData, std::shared_ptr<VolumeData>>(m, "VolumeData")
      .def(py::init(&from_array), py::arg("labels"), py::kw_only(),
           py::arg("dimensions") = py::none(), py::arg("voxel_size") = py::none(),
           py::arg("label_table") = py::none(),
           "A volume from a (nx, ny, nz) uint8/uint16 label array (copied), its size in metres "
           "and its labels (a list of Label or a CSV/YAML file; named label_<id> when absent).")
      .def_property_readonly(
          "labels",
          [](py::object self) {
            auto& v = self.cast<VolumeData&>();
            return grid_view(self, v, v.label_data(), label_dtype(v.label_type()), true);
          },
          "(nx, ny, nz) view of the label grid, i fastest in memory; after writing through it, "
          "call mark_dirty() so renderers see the change")
      .def_property_readonly(
          "intensity",
          [](py::object self) -> py::object {
            auto& v = self.cast<VolumeData&>();
            if (v.intensity_type() == IntensityType::kNone) return py::none();
            return grid_view(self, v, v.intensity_data(),
                             v.intensity_type() == IntensityType::kInt16
                                 ? py::dtype::of<std::int16_t>()
                                 : py::dtype::of<float>(),
                             true);
          },
          "(nx, ny, nz) view of the intensity (CT) grid, or None; after writing through it, call "
          "mark_intensity_changed() so renderers see the change")
      .def(
          "mark_intensity_changed",
          [](VolumeData& v) {
            py::gil_scoped_release release;
            v.mark_intensity_changed();
          },
          "declares the intensity grid changed through its view: renderers read it again")
      .def_property_readonly(
          "smoothed_occupancy",
          [](py::object self) {
            auto& v = self.cast<VolumeData&>();
            auto& field = const_cast<std::vector<std::uint8_t>&>(v.smoothed_occupancy());
            return grid_view(self, v, field.data(), py::dtype::of<std::uint8_t>(), false);
          },
          "read-only (nx, ny, nz) view of the blurred occupancy (0..255) whose 0.5 level is the "
          "rendered surface, brought up to date with the edits made since whenever it is read "
          "(a view taken earlier shows it as of then until it, or raycast, is read again); "
          "while a real-time loop drills this data, read it under world.lock()")
      .def_property_readonly("shape",
                             [](const VolumeData& v) {
                               return py::make_tuple(v.shape()[0], v.shape()[1], v.shape()[2]);
                             })
      .def_property(
          "dimensions", [](const VolumeData& v) { return Vec3(v.dimensions()); },
          [](VolumeData& v, const Vec3& d) {
            check_volume_sizes(d, "VolumeData.dimensions");
            v.set_dimensions(d);
          },
          "full extents along x, y, z, metres")
      .def_property_readonly("voxel_size", &VolumeData::voxel_size)
      .def_property_readonly("label_type",
                             [](const VolumeData& v) {
                               return v.label_type() == LabelType::kUInt8 ? "uint8" : "uint16";
                             })
      .def_property(
          "label_table", [](const VolumeData& v) { return v.label_table().labels(); },
          [](VolumeData& v, const std::vector<Label>& labels) {
            v.set_label_table(LabelTable(labels));
          })
      .def(
          "label",
          [](const VolumeData& v, const py::object& key) {
            const Label* l = py::isinstance<py::str>(key)
                                 ? v.label_table().find(key.cast<std::string>())
                                 : v.label_table().find(key.cast<std::uint16_t>());
            if (l == nullptr)
              throw NotFound("no label " + py::repr(key).cast<std::string>() + " in the table");
            return *l;
          },
          py::arg("id_or_name"))
      .def(
          "label_ids",
          [](const VolumeData& v, const py::handle& labels, const std::string& what) {
            return structure_labels(v, labels, what);
          },
          py::arg("labels"), py::arg("what") = "labels",
          "The ids of labels given by name or id (one, or a list), by the rule every caller uses "
          "(a name first, then a number); an unknown one raises NotFound starting with `what` "
          "and listing the table's labels.")
      .def(
          "label_counts",
          [](const VolumeData& v) {
            const auto counts = v.label_counts();
            return py::array_t<std::int64_t>(py::ssize_t(counts.size()), counts.data());
          },
          "voxels per label id (index = id; index 0 counts the empty voxels)")
      .def("voxel_center", &VolumeData::voxel_center, py::arg("i"), py::arg("j"), py::arg("k"),
           "centre of voxel (i, j, k) in the volume frame")
      .def_property_readonly(
          "patient_from_volume",
          [](const VolumeData& v) { return Eigen::Matrix4d(v.patient_from_volume()); })
      .def_property_readonly("source", &VolumeData::source)
      .def_property_readonly("revision", &VolumeData::revision)
      .def(
          "remove_sphere",
          [](VolumeData& v, const Vec3& c, double r, bool only_removable) {
            py::gil_scoped_release release;
            return v.remove_sphere(c, r, only_removable);
          },
          py::arg("center"), py::arg("radius"), py::arg("only_removable") = true,
          "clears the voxels whose centres are within radius of center (volume frame, metres)")
      .def(
          "set_region",
          [](VolumeData& v, std::array<int, 3> lo, std::array<int, 3> hi, int label) {
            if (label < 0 || label > 65535) throw ArgumentError("label must be 0..65535");
            py::gil_scoped_release release;
            return v.set_region(VoxelBox{lo, hi}, static_cast<std::uint16_t>(label));
          },
          py::arg("lo"), py::arg("hi"), py::arg("label"), "sets voxels [lo, hi) to label")
      .def(
          "mark_dirty",
          [](VolumeData& v, std::optional<std::array<int, 3>> lo,
             std::optional<std::array<int, 3>> hi) {
            const VoxelBox box = box_from(lo, hi, v);
            py::gil_scoped_release release;
            v.mark_dirty(box);
          },
          py::arg("lo") = py::none(), py::arg("hi") = py::none(),
          "declares voxels [lo, hi) (default: all) changed through the labels view")
      .def(
          "reset",
          [](VolumeData& v) {
            py::gil_scoped_release release;
            v.reset();
          },
          "restores the labels as loaded (or last committed)")
      .def(
          "commit",
          [](VolumeData& v) {
            py::gil_scoped_release release;
            v.commit();
          },
          "makes the current labels what reset() restores")
      .def_property_readonly(
          "edit_log",
          [](const VolumeData& v) {
            py::list out;
            for (const VolumeEdit& e : v.edit_log()) out.append(edit_dict(e));
            return out;
          },
          "the edits so far: dicts of revision, kind, box, changed, voxels, old_labels")
      .def(
          "take_edit_log",
          [](VolumeData& v) {
            py::list out;
            for (const VolumeEdit& e : v.take_edit_log()) out.append(edit_dict(e));
            return out;
          },
          "returns the edit log and starts a new one")
      .def_property_readonly(
          "edit_log_dropped", &VolumeData::edit_log_dropped,
          "edits dropped from the log because it was full (it keeps the newest "
          "VolumeData.EDIT_LOG_EDITS edits, holding at most VolumeData.EDIT_LOG_VOXELS voxels)")
      .def_readonly_static("EDIT_LOG_EDITS", &VolumeData::kEditLogEdits,
                           "edits kept in the log until taken")
      .def_readonly_static("EDIT_LOG_VOXELS", &VolumeData::kEditLogVoxels,
                           "removed voxels the kept edits hold at most")
      .def(
          "raycast",
          [](VolumeData& v, const Vec3& origin, const Vec3& direction, double iso) {
            VolumeHit h;
            {
              py::gil_scoped_release release;
              h = v.raycast(origin, direction, iso);
            }
            return hit_dict(h);
          },
          py::arg("origin"), py::arg("direction"), py::arg("iso") = 0.5,
          "first iso-surface hit of a volume-frame ray: dict(distance, position, normal, label) "
          "or None (it brings the smoothed field up to date: while a real-time loop drills this "
          "data, call it under world.lock(), or use Volume.raycast, which takes the lock)")
      .def(
          "save_nrrd",
          [](const VolumeData& v, const std::filesystem::path& path, const std::string& what,
             bool gzip) {
            py::gil_scoped_release release;
            save_nrrd(v, path.string(), what, gzip);
          },
          py::arg("path"), py::arg("what") = "labels", py::arg("gzip") = true)
      .def(
          "save_slice_stack",
          [](const VolumeData& v, const std::filesystem::path& folder, const std::string& prefix,
             const std::string& format) {
            py::gil_scoped_release release;
            save_slice_stack(v, folder.string(), prefix, format);
          },
          py::arg("folder"), py::arg("prefix") = "plane00", py::arg("format") = "png")
      .def(
          "save_mesh",
          [](VolumeData& v, const std::filesystem::path& path, int label, double iso) {
            py::gil_scoped_release release;
            return write_surface_mesh(v, path.string(), static_cast<std::uint16_t>(label), iso);
          },
          py::arg("path"), py::arg("label") = 0, py::arg("iso") = 0.5,
          "writes the iso-surface (of one label, or of all when 0) as .stl or .ply; returns the "
          "triangle count")
      .def("__repr__", [](const VolumeData& v) {
        std::ostringstream s;
        s << "<VolumeData " << v.shape()[0] << "x" << v.shape()[1] << "x" << v.shape()[2] << " "
          << (v.label_type() == LabelType::kUInt8 ? "uint8" : "uint16") << ", "
          << v.label_table().size() << " labels, " << v.dimensions().transpose() * 1000 << " mm>";
        return s.str();
      });

  m.def(
      "load_slice_stack",
      [](const std::filesystem::path& folder, const std::string& prefix, const std::string& format,
         int count, std::optional<Vec3> dimensions, std::optional<Vec3> voxel_size,
         const py::object& labels, int alpha_threshold) {
        if (dimensions && voxel_size)
          throw ArgumentError("give dimensions or voxel_size, not both");
        if (!dimensions && !voxel_size) {
          throw ArgumentError("give the stack's size: dimensions=(x, y, z) metres or voxel_size=");
        }
        // Checked before the slices are read, naming the argument.
        const std::string call = "load_slice_stack(" + folder.string() + "): ";
        if (dimensions) check_volume_sizes(*dimensions, call + "dimensions");
        if (voxel_size) check_volume_sizes(*voxel_size, call + "voxel_size");
        SliceStackSpec spec;
        spec.folder = folder.string();
        if (dimensions) spec.dimensions = *dimensions;
        spec.prefix = prefix;
        spec.format = format;
        spec.count = count;
        spec.labels = table_from(labels);
        spec.alpha_threshold = alpha_threshold;
        std::shared_ptr<VolumeData> v;
        {
          py::gil_scoped_release release;
          v = load_slice_stack(spec);
        }
        const auto& n = v->shape();
        v->set_dimensions(dimensions ? *dimensions
                                     : voxel_size->cwiseProduct(Vec3(n[0], n[1], n[2])));
        return v;
      },
      py::arg("folder"), py::arg("prefix") = "plane00", py::arg("format") = "png",
      py::arg("count") = -1, py::kw_only(), py::arg("dimensions") = py::none(),
      py::arg("voxel_size") = py::none(), py::arg("labels") = py::none(),
      py::arg("alpha_threshold") = 128,
      "Loads an AMBF slice stack: pixel (row r, column c) of slice k is voxel (c, H-1-r, k).");

  m.def(
      "load_nrrd",
      [](const std::filesystem::path& path, const std::string& kind,
         std::optional<double> threshold) {
        NrrdOptions o;
        if (kind == "auto") {
          o.kind = NrrdOptions::Kind::kAuto;
        } else if (kind == "labels") {
          o.kind = NrrdOptions::Kind::kLabels;
        } else if (kind == "intensity") {
          o.kind = NrrdOptions::Kind::kIntensity;
        } else if (kind == "segmentation") {
          o.kind = NrrdOptions::Kind::kSegmentation;
        } else {
          throw ArgumentError("kind must be auto, labels, intensity or segmentation");
        }
        o.threshold = threshold;
        py::gil_scoped_release release;
        return load_nrrd(path.string(), o);
      },
      py::arg("path"), py::arg("kind") = "auto", py::arg("threshold") = py::none(),
      "Loads an NRRD label map, intensity volume (segmented by threshold) or 3D Slicer "
      "segmentation (.seg.nrrd).");

  m.def(
      "phantom",
      [](int resolution, std::uint32_t seed, const std::string& side) {
        const PhantomSide s = parse_phantom_side(side);
        py::gil_scoped_release release;
        return make_temporal_bone_phantom(resolution, seed, s);
      },
      py::arg("resolution") = 128, py::arg("seed") = 0, py::arg("side") = "right",
      "The built-in procedural temporal bone (48 mm cube, lateral face towards +z; side "
      "\"right\" or \"left\"), labelled like the original system's segmented ear.");

  m.def(
      "read_label_table",
      [](const std::filesystem::path& path) { return read_label_table(path.string()).labels(); },
      py::arg("path"));

  m.def(
      "write_label_table",
      [](const std::filesystem::path& path, const std::vector<Label>& labels) {
        write_label_table(path.string(), LabelTable(labels));
      },
      py::arg("path"), py::arg("labels"));

  bound<DistanceField, std::shared_ptr<DistanceField>>(m, "DistanceField")
      .def(py::init(
               [](const std::shared_ptr<VolumeData>& data, const py::handle& labels, double band) {
                 auto ids = structure_labels(*data, labels, "DistanceField");
                 py::gil_scoped_release release;
                 return std::make_shared<DistanceField>(*data, std::move(ids), band);
               }),
           py::arg("volume"), py::arg("labels"), py::arg("band") = 0.005, py::keep_alive<1, 2>(),
           "The field of the structure made of `labels` (names or ids, one or a list) in "
           "`volume`, clamped to `band` metres.")
      .def(
          "update",
          [](DistanceField& f) {
            py::gil_scoped_release release;
            return f.update();
          },
          "Brings the field up to the volume's edits; returns the voxels recomputed.")
      .def_property_readonly("revision", &DistanceField::revision)
      .def_property_readonly("band", &DistanceField::band)
      .def_property_readonly("labels", &DistanceField::labels)
      .def_property_readonly("structure_voxels", &DistanceField::structure_voxels)
      .def("at", &DistanceField::at, py::arg("i"), py::arg("j"), py::arg("k"),
           "The signed distance at voxel (i, j, k)'s centre (metres).")
      .def(
          "sample",
          [](const DistanceField& f,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& points)
              -> py::object {
            if (points.ndim() == 1 && points.shape(0) == 3) {
              const DistanceSample s =
                  f.sample(Eigen::Vector3d(points.at(0), points.at(1), points.at(2)));
              py::array_t<double> g(3);
              for (int a = 0; a < 3; ++a) g.mutable_at(a) = s.gradient[a];
              return py::make_tuple(s.distance, g);
            }
            if (points.ndim() != 2 || points.shape(1) != 3) {
              throw ArgumentError("DistanceField.sample: expected a point (3,) or points (N, 3)");
            }
            const py::ssize_t n = points.shape(0);
            py::array_t<double> d(n), g({n, py::ssize_t(3)});
            const double* p = points.data();
            double* dp = d.mutable_data();
            double* gp = g.mutable_data();
            {
              py::gil_scoped_release release;
              for (py::ssize_t r = 0; r < n; ++r) {
                const DistanceSample s =
                    f.sample(Eigen::Vector3d(p[3 * r], p[3 * r + 1], p[3 * r + 2]));
                dp[r] = s.distance;
                for (int a = 0; a < 3; ++a) gp[3 * r + a] = s.gradient[a];
              }
            }
            return py::make_tuple(d, g);
          },
          py::arg("points"),
          "(distance, gradient) at a volume-frame point (3,), or arrays for points (N, 3): "
          "trilinear in the voxel-centre values, with that interpolant's gradient.")
      .def(
          "values",
          [](const DistanceField& f) {
            auto values = std::make_unique<std::vector<float>>(f.values());
            const auto& n = f.volume().shape();
            float* data = values->data();
            py::capsule owner(values.release(),
                              [](void* v) { delete static_cast<std::vector<float>*>(v); });
            const py::ssize_t s = sizeof(float);
            return py::array_t<float>({py::ssize_t(n[0]), py::ssize_t(n[1]), py::ssize_t(n[2])},
                                      {s, s * n[0], s * n[0] * n[1]}, data, owner);
          },
          "The signed distance of every voxel as a (nx, ny, nz) float32 array (a copy).");
}

}  // namespace ambfplus::bindings
