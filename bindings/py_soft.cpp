// Soft bodies, proximity sensors and constraint actuators.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "ambfplus/scene/model.h"
#include "ambfplus/scene/simulator.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

template <typename T>
std::shared_ptr<T> handle(T* p) {
  return std::shared_ptr<T>(p->world().simulator().shared_from_this(), p);
}

// A read-only (rows, 3) NumPy view of `data`, kept alive by `owner`.
template <typename T>
py::array rows_view(py::object owner, const T* data, std::size_t rows) {
  const auto s = static_cast<py::ssize_t>(sizeof(T));
  py::array a(py::dtype::of<T>(), {static_cast<py::ssize_t>(rows), py::ssize_t(3)}, {3 * s, s},
              data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array_t<double> rows_copy(const std::vector<double>& xyz) {
  py::array_t<double> out({static_cast<py::ssize_t>(xyz.size() / 3), py::ssize_t(3)});
  std::copy(xyz.begin(), xyz.end(), out.mutable_data());
  return out;
}

std::array<float, 4> parse_color(const py::handle& v) {
  const auto c = v.cast<std::vector<double>>();
  if (c.size() != 3 && c.size() != 4) {
    throw py::value_error("color must be (r, g, b) or (r, g, b, a) in 0..1");
  }
  std::array<float, 4> out{0, 0, 0, 1};
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!(c[i] >= 0.0 && c[i] <= 1.0)) throw py::value_error("color components must be in 0..1");
    out[i] = static_cast<float>(c[i]);
  }
  return out;
}

// A node index list: ints in range, as a vector.
std::vector<int> node_list(const SoftBody& s, const py::handle& v) {
  std::vector<int> nodes = v.cast<std::vector<int>>();
  const int count = static_cast<int>(s.node_count());
  for (int n : nodes) {
    if (n < 0 || n >= count) {
      throw py::index_error("soft body '" + s.name() + "' has nodes 0.." +
                            std::to_string(count - 1) + ", not " + std::to_string(n));
    }
  }
  return nodes;
}

// The AMBF `config` block as a dict: kLST ... citerations, flags, `bending constraint`,
// clusters, `fixed nodes` (spaces or underscores).
void apply_config(SoftBodyConfig& c, const py::dict& d) {
  for (auto item : d) {
    const std::string key = py::str(item.first);
    if (key == "fixed nodes" || key == "fixed_nodes") {
      c.fixed_nodes = item.second.cast<std::vector<int>>();
      continue;
    }
    if (!set_soft_body_config(c, key, item.second.cast<double>())) {
      throw py::value_error(
          "unknown soft body config key '" + key +
          "': expected kLST, kAST, kVST, kVCF, kDP, kDG, kLF, kPR, kVC, kDF, kMT, kCHR, kKHR, "
          "kSHR, kAHR, kSRHR_CL, kSKHR_CL, kSSHR_CL, kSR_SPLT_CL, kSK_SPLT_CL, kSS_SPLT_CL, "
          "maxvolume, timescale, viterations, piterations, diterations, citerations, flags, "
          "bending constraint, clusters or fixed nodes");
    }
  }
}

// Each ray's start or end, (N, 3), world frame.
py::array_t<double> ray_points(const ProximitySensor& s,
                               Vec3 (ProximitySensor::*point)(int) const) {
  std::vector<double> xyz;
  for (int i = 0; i < static_cast<int>(s.ray_count()); ++i) {
    const Vec3 p = (s.*point)(i);
    xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  }
  return rows_copy(xyz);
}

py::dict config_dict(const SoftBodyConfig& c) {
  py::dict d;
  d["kLST"] = c.linear_stiffness;
  d["kAST"] = c.area_stiffness;
  d["kVST"] = c.volume_stiffness;
  d["kVCF"] = c.velocity_correction;
  d["kDP"] = c.damping;
  d["kDG"] = c.drag;
  d["kLF"] = c.lift;
  d["kPR"] = c.pressure;
  d["kVC"] = c.volume_conservation;
  d["kDF"] = c.dynamic_friction;
  d["kMT"] = c.pose_matching ? py::cast(*c.pose_matching) : py::none();
  d["kCHR"] = c.rigid_hardness;
  d["kKHR"] = c.kinetic_hardness;
  d["kSHR"] = c.soft_hardness;
  d["kAHR"] = c.anchor_hardness;
  d["kSRHR_CL"] = c.cluster_rigid_hardness;
  d["kSKHR_CL"] = c.cluster_kinetic_hardness;
  d["kSSHR_CL"] = c.cluster_soft_hardness;
  d["kSR_SPLT_CL"] = c.cluster_rigid_impulse_split;
  d["kSK_SPLT_CL"] = c.cluster_kinetic_impulse_split;
  d["kSS_SPLT_CL"] = c.cluster_soft_impulse_split;
  d["maxvolume"] = c.max_volume;
  d["timescale"] = c.time_scale;
  d["viterations"] = c.velocity_iterations;
  d["piterations"] = c.position_iterations;
  d["diterations"] = c.drift_iterations;
  d["citerations"] = c.cluster_iterations;
  d["flags"] = c.collision_flags;
  d["bending constraint"] = c.bending_constraint ? py::cast(*c.bending_constraint) : py::none();
  d["clusters"] = c.clusters ? py::cast(*c.clusters) : py::none();
  d["fixed nodes"] = c.fixed_nodes;
  return d;
}

// A location on the parent: `location` (parent frame) or `pose` (world frame), not both.
Mat4 parent_location(const RigidBody& parent, const py::handle& location, const py::handle& pose,
                     const char* what) {
  if (!location.is_none() && !pose.is_none()) {
    throw py::value_error(std::string(what) +
                          ": give location (in the parent's frame) or pose (world), not both");
  }
  if (!location.is_none()) return location.cast<Mat4>();
  if (!pose.is_none()) {
    return (parent.pose().inverse() * checked_pose(pose.cast<Mat4>())).matrix();
  }
  return Mat4::Identity();
}

// A ray from {offset, direction} or (offset, direction).
SensorRay parse_ray(const py::handle& v) {
  SensorRay r;
  if (py::isinstance<py::dict>(v)) {
    for (auto item : v.cast<py::dict>()) {
      const std::string key = py::str(item.first);
      if (key == "offset") {
        r.offset = item.second.cast<Vec3>();
      } else if (key == "direction") {
        r.direction = item.second.cast<Vec3>();
      } else {
        throw py::value_error("a ray takes offset and direction, got '" + key + "'");
      }
    }
    return r;
  }
  const auto pair = v.cast<std::pair<Vec3, Vec3>>();
  r.offset = pair.first;
  r.direction = pair.second;
  return r;
}

py::object hit_object(const SensorHit& h) {
  if (h.body != nullptr) return py::cast(handle(h.body));
  if (h.soft_body != nullptr) return py::cast(handle(h.soft_body));
  return py::none();
}

py::dict hit_to_dict(const SensorHit& h) {
  py::dict d;
  d["triggered"] = h.triggered;
  d["distance"] = h.distance;
  d["fraction"] = h.fraction;
  d["point"] = Vec3(h.point);
  d["normal"] = Vec3(h.normal);
  d["body"] = hit_object(h);
  d["node"] = h.soft_body_node >= 0 ? py::cast(h.soft_body_node) : py::none();
  return d;
}

}  // namespace

SoftBody& add_soft_body(Model& model, const std::string& name, const std::string& mesh,
                        const py::kwargs& kw) {
  SoftBodySpec spec;
  spec.name = name;
  spec.mesh = mesh;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "scale") {
      spec.scale = v.cast<double>();
    } else if (key == "pose") {
      if (!v.is_none()) spec.pose = v.cast<Mat4>();
    } else if (key == "mass") {
      spec.mass = v.cast<double>();
    } else if (key == "margin") {
      spec.margin = v.cast<double>();
    } else if (key == "config") {
      if (!v.is_none()) apply_config(spec.config, v.cast<py::dict>());
    } else if (key == "fixed_nodes") {
      spec.config.fixed_nodes = v.cast<std::vector<int>>();
    } else if (key == "randomize_constraints") {
      spec.randomize_constraints = v.cast<bool>();
    } else if (key == "color") {
      spec.material.color = parse_color(v);
    } else if (key == "specular") {
      spec.material.specular = v.cast<float>();
    } else if (key == "shininess") {
      spec.material.shininess = v.cast<float>();
    } else {
      throw py::type_error("add_soft_body() got an unexpected keyword argument '" + key + "'");
    }
  }
  SoftBody* body = nullptr;
  {
    py::gil_scoped_release release;  // reads a mesh file
    body = &model.add_soft_body(spec);
  }
  return *body;
}

ProximitySensor& add_sensor(Model& model, const std::string& name, RigidBody& parent,
                            const py::kwargs& kw) {
  ProximitySensorSpec spec;
  spec.name = name;
  spec.parent = &parent;
  py::object location = py::none(), pose = py::none();
  std::optional<Vec3> offset, direction;
  bool rays_given = false;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "location") {
      location = py::reinterpret_borrow<py::object>(v);
    } else if (key == "pose") {
      pose = py::reinterpret_borrow<py::object>(v);
    } else if (key == "range") {
      spec.range = v.cast<double>();
    } else if (key == "offset") {
      offset = v.cast<Vec3>();
    } else if (key == "direction") {
      direction = v.cast<Vec3>();
    } else if (key == "rays") {
      rays_given = true;
      for (const py::handle r : v) spec.rays.push_back(parse_ray(r));
    } else if (key == "parametric") {
      rays_given = true;
      const auto p = v.cast<py::dict>();
      auto get = [&](const char* a, const char* b) -> py::object {
        if (p.contains(a)) return p[a];
        if (p.contains(b)) return p[b];
        throw py::value_error(std::string("parametric needs '") + a + "'");
      };
      for (auto k : p) {
        const std::string n = py::str(k.first);
        if (n != "resolution" && n != "horizontal angle" && n != "horizontal_angle" &&
            n != "vertical angle" && n != "vertical_angle" && n != "start offset" &&
            n != "start_offset") {
          throw py::value_error(
              "parametric takes resolution, horizontal angle, vertical angle and start offset, "
              "got '" +
              n + "'");
        }
      }
      const double start =
          p.contains("start offset")
              ? p["start offset"].cast<double>()
              : (p.contains("start_offset") ? p["start_offset"].cast<double>() : 0.0);
      const auto fan =
          parametric_sensor_rays(get("resolution", "resolution").cast<int>(),
                                 get("horizontal angle", "horizontal_angle").cast<double>(),
                                 get("vertical angle", "vertical_angle").cast<double>(), start);
      spec.rays.insert(spec.rays.end(), fan.begin(), fan.end());
    } else if (key == "visible") {
      spec.visible = v.cast<bool>();
    } else if (key == "visible_size") {
      spec.visible_size = v.cast<double>();
    } else {
      throw py::type_error("add_sensor() got an unexpected keyword argument '" + key + "'");
    }
  }
  if (rays_given && (offset || direction)) {
    throw py::value_error("sensor '" + name +
                          "': give rays (or parametric), or one ray by offset and direction, "
                          "not both");
  }
  if (!rays_given) {
    SensorRay r;
    if (offset) r.offset = *offset;
    if (direction) r.direction = *direction;
    spec.rays.push_back(r);
  }
  spec.location = parent_location(parent, location, pose, ("sensor '" + name + "'").c_str());
  return model.add_sensor(spec);
}

ConstraintActuator& add_actuator(Model& model, const std::string& name, RigidBody& parent,
                                 const py::kwargs& kw) {
  ConstraintActuatorSpec spec;
  spec.name = name;
  spec.parent = &parent;
  py::object location = py::none(), pose = py::none();
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "location") {
      location = py::reinterpret_borrow<py::object>(v);
    } else if (key == "pose") {
      pose = py::reinterpret_borrow<py::object>(v);
    } else if (key == "max_impulse") {
      spec.max_impulse = v.cast<double>();
    } else if (key == "tau") {
      spec.tau = v.cast<double>();
    } else if (key == "hold") {
      const std::string h = v.cast<std::string>();
      if (h == "fixed") {
        spec.hold = ActuatorHold::kFixed;
      } else if (h == "point") {
        spec.hold = ActuatorHold::kPoint;
      } else {
        throw py::value_error("hold must be 'fixed' or 'point', got '" + h + "'");
      }
    } else if (key == "visible") {
      spec.visible = v.cast<bool>();
    } else if (key == "visible_size") {
      spec.visible_size = v.cast<double>();
    } else {
      throw py::type_error("add_actuator() got an unexpected keyword argument '" + key + "'");
    }
  }
  spec.location = parent_location(parent, location, pose, ("actuator '" + name + "'").c_str());
  return model.add_actuator(spec);
}

void register_soft(
    py::module_& m, py::class_<SoftBody, Object, std::shared_ptr<SoftBody>>& soft,
    py::class_<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>& sensor,
    py::class_<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>& actuator) {
  soft.def_property_readonly("mesh", [](SoftBody& s) { return s.spec().mesh; })
      .def_property_readonly("mass", &SoftBody::mass, "kg, shared evenly by the nodes")
      .def_property_readonly(
          "margin", [](SoftBody& s) { return s.spec().margin; }, "collision margin, m")
      .def_property_readonly(
          "config", [](SoftBody& s) { return config_dict(s.spec().config); },
          "the AMBF config coefficients it was created with (a copy)")
      .def_property_readonly("node_count", &SoftBody::node_count)
      .def_property_readonly(
          "nodes",
          [](py::object self) {
            const SoftBody& s = self.cast<const SoftBody&>();
            return rows_view(self, s.node_positions().data(), s.node_count());
          },
          "(N, 3) float64 node positions, world frame: a read-only view refreshed by every step "
          "(node i is the mesh's i-th distinct vertex)")
      .def_property_readonly(
          "triangles",
          [](py::object self) {
            const SoftBody& s = self.cast<const SoftBody&>();
            return rows_view(self, s.triangles().data(), s.triangles().size() / 3);
          },
          "(M, 3) uint32 node indices of the faces (read-only view)")
      .def_property_readonly(
          "node_velocities", [](SoftBody& s) { return rows_copy(s.node_velocities()); },
          "(N, 3) float64 node velocities, world frame, m/s (a copy)")
      .def(
          "set_node_positions",
          [](SoftBody& s, const py::object& nodes, const Eigen::MatrixX3d& positions) {
            const std::vector<int> list = node_list(s, nodes);
            if (static_cast<Eigen::Index>(list.size()) != positions.rows()) {
              throw py::value_error("set_node_positions: " + std::to_string(list.size()) +
                                    " nodes but " + std::to_string(positions.rows()) +
                                    " positions");
            }
            for (std::size_t i = 0; i < list.size(); ++i) {
              s.set_node_position(list[i], positions.row(static_cast<Eigen::Index>(i)));
            }
          },
          py::arg("nodes"), py::arg("positions"),
          "Moves nodes (indices) to positions ((K, 3), world frame) at once.")
      .def(
          "fix_nodes",
          [](SoftBody& s, const py::object& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, true);
          },
          py::arg("nodes"), "Pins nodes (indices) where they are.")
      .def(
          "release_nodes",
          [](SoftBody& s, const py::object& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, false);
          },
          py::arg("nodes"), "Lets pinned nodes move again.")
      .def_property_readonly("fixed_nodes", &SoftBody::fixed_nodes, "pinned node indices")
      .def_property(
          "color", [](SoftBody& s) { return s.material().color; },
          [](SoftBody& s, const py::object& c) {
            Material mat = s.material();
            mat.color = parse_color(c);
            s.set_material(mat);
          },
          "RGBA in 0..1")
      .def_property(
          "shader", [](SoftBody& s) { return from_shader(s.material().shader); },
          [](SoftBody& s, const py::object& v) {
            Material mat = s.material();
            mat.shader = to_shader(v, "shader");
            s.set_material(mat);
          },
          "its own shader: None (its model's), 'builtin', or (vertex_path, fragment_path)");

  sensor.def_property_readonly("parent", [](ProximitySensor& s) { return handle(&s.parent()); })
      .def_property_readonly(
          "location", [](ProximitySensor& s) { return Mat4(s.spec().location); },
          "4x4 sensor frame in the parent's frame")
      .def_property("range", &ProximitySensor::range, &ProximitySensor::set_range,
                    "m each ray reaches (per unit of its direction)")
      .def_property_readonly("ray_count", &ProximitySensor::ray_count)
      .def_property_readonly("triggered", &ProximitySensor::triggered, "whether any ray hits")
      .def_property_readonly(
          "hits",
          [](ProximitySensor& s) {
            py::list out;
            for (const SensorHit& h : s.hits()) out.append(hit_to_dict(h));
            return out;
          },
          "per ray: dict(triggered, distance (m from the ray's start; its length on a miss), "
          "fraction, point, normal (world), body (RigidBody, SoftBody or None), node (soft "
          "body's nearest node or None))")
      .def_property_readonly(
          "distances",
          [](ProximitySensor& s) {
            py::array_t<double> out(static_cast<py::ssize_t>(s.ray_count()));
            for (std::size_t i = 0; i < s.ray_count(); ++i)
              out.mutable_at(i) = s.hits()[i].distance;
            return out;
          },
          "(N,) m from each ray's start to its hit (its length on a miss)")
      .def_property_readonly(
          "triggered_rays",
          [](ProximitySensor& s) {
            py::array_t<bool> out(static_cast<py::ssize_t>(s.ray_count()));
            for (std::size_t i = 0; i < s.ray_count(); ++i) {
              out.mutable_at(i) = s.hits()[i].triggered;
            }
            return out;
          },
          "(N,) bool, whether each ray hits")
      .def_property_readonly(
          "ray_starts",
          [](ProximitySensor& s) { return ray_points(s, &ProximitySensor::ray_start); },
          "(N, 3) world frame")
      .def_property_readonly(
          "ray_ends", [](ProximitySensor& s) { return ray_points(s, &ProximitySensor::ray_end); },
          "(N, 3) world frame")
      .def("update", &ProximitySensor::update,
           "Casts the rays now (the world does it after every physics step).");

  actuator
      .def_property_readonly("parent", [](ConstraintActuator& a) { return handle(&a.parent()); })
      .def_property_readonly(
          "location", [](ConstraintActuator& a) { return Mat4(a.location().matrix()); },
          "4x4 actuator frame in the parent's frame")
      .def_property_readonly("max_impulse",
                             [](ConstraintActuator& a) { return a.spec().max_impulse; })
      .def_property_readonly("tau", [](ConstraintActuator& a) { return a.spec().tau; })
      .def_property_readonly("hold",
                             [](ConstraintActuator& a) {
                               return a.spec().hold == ActuatorHold::kFixed ? "fixed" : "point";
                             })
      .def(
          "actuate",
          [](ConstraintActuator& a, RigidBody& body, const py::object& offset) {
            if (offset.is_none()) {
              a.actuate(body);
              return;
            }
            const py::array arr = py::array::ensure(offset);
            if (arr && arr.ndim() == 2) {
              a.actuate(body, checked_pose(offset.cast<Mat4>()));
            } else {
              Eigen::Isometry3d o = Eigen::Isometry3d::Identity();
              o.translation() = offset.cast<Vec3>();
              a.actuate(body, o);
            }
          },
          py::arg("body"), py::arg("offset") = py::none(),
          "Holds body: where it is now, or with the actuator at offset in the body's frame (a "
          "point, or a 4x4 frame), pulling it there. A body already held stays held.")
      .def("deactuate", &ConstraintActuator::deactuate, "Releases the body held.")
      .def("is_actuated", &ConstraintActuator::is_actuated)
      .def_property_readonly(
          "actuated_body",
          [](ConstraintActuator& a) -> py::object {
            return a.actuated_body() ? py::cast(handle(a.actuated_body())) : py::none();
          },
          "the body held, or None");
}

}  // namespace ambfplus::bindings
