#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>

#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/six_dof.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

int parse_axis(const py::handle& v) {
  if (py::isinstance<py::str>(v)) {
    const std::string a = v.cast<std::string>();
    if (a == "x") return 0;
    if (a == "y") return 1;
    if (a == "z") return 2;
    throw py::value_error("axis must be 'x', 'y' or 'z', got '" + a + "'");
  }
  return v.cast<int>();
}

ControlOutput parse_output(const std::string& s) {
  if (s == "effort" || s == "force") return ControlOutput::kEffort;
  if (s == "velocity") return ControlOutput::kVelocity;
  throw py::value_error("controller output must be 'effort' or 'velocity', got '" + s + "'");
}

// Updates `c` with the keys given.
JointController parse_controller(const py::dict& d, JointController c) {
  for (auto item : d) {
    const std::string key = py::str(item.first);
    if (key == "p") {
      c.p = item.second.cast<double>();
    } else if (key == "i") {
      c.i = item.second.cast<double>();
    } else if (key == "d") {
      c.d = item.second.cast<double>();
    } else if (key == "output") {
      c.output = parse_output(item.second.cast<std::string>());
    } else {
      throw py::value_error("controller keys are p, i, d and output, got '" + key + "'");
    }
  }
  return c;
}

py::dict controller_dict(const JointController& c) {
  py::dict d;
  d["p"] = c.p;
  d["i"] = c.i;
  d["d"] = c.d;
  d["output"] = c.output == ControlOutput::kEffort ? "effort" : "velocity";
  return d;
}

// A compound part: {"shape": "box", "size": ..., "radius": ..., "height": ..., "axis": ...,
// "pose": 4x4}.
std::pair<Shape, Mat4> parse_part(const py::dict& d) {
  Shape s;
  Mat4 pose = Mat4::Identity();
  for (auto item : d) {
    const std::string key = py::str(item.first);
    if (key == "shape") {
      s.kind = parse_shape_kind(item.second.cast<std::string>());
    } else if (key == "size") {
      s.size = item.second.cast<Vec3>();
    } else if (key == "radius") {
      s.radius = item.second.cast<double>();
    } else if (key == "height") {
      s.height = item.second.cast<double>();
    } else if (key == "axis") {
      s.axis = parse_axis(item.second);
    } else if (key == "pose") {
      pose = item.second.cast<Mat4>();
    } else {
      throw py::value_error(
          "compound parts take shape, size, radius, height, axis and pose, got '" + key + "'");
    }
  }
  return {s, pose};
}

}  // namespace

void apply_body_options(RigidBodySpec& spec, const py::kwargs& kw) {
  Dynamics& d = spec.dynamics;
  Collision& c = spec.collision;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "inertia") {
      d.inertia = v.cast<Vec3>();
    } else if (key == "inertial_offset") {
      d.inertial_offset = v.cast<Mat4>();
    } else if (key == "friction") {
      d.static_friction = v.cast<double>();
    } else if (key == "rolling_friction") {
      d.rolling_friction = v.cast<double>();
    } else if (key == "restitution") {
      d.restitution = v.cast<double>();
    } else if (key == "linear_damping") {
      d.linear_damping = v.cast<double>();
    } else if (key == "angular_damping") {
      d.angular_damping = v.cast<double>();
    } else if (key == "kinematic") {
      d.kinematic = v.cast<bool>();
    } else if (key == "collision") {
      c.enabled = v.cast<bool>();
    } else if (key == "collision_mesh") {
      c.mesh = v.cast<std::string>();
    } else if (key == "collision_type") {
      c.mesh_type = parse_mesh_collision(v.cast<std::string>());
    } else if (key == "collision_shapes") {
      for (const py::handle part : v) c.shapes.push_back(parse_part(part.cast<py::dict>()));
    } else if (key == "margin") {
      c.margin = v.cast<double>();
    } else if (key == "groups") {
      for (int g : v.cast<std::vector<int>>()) {
        if (g < 0 || g > 31) throw py::value_error("collision groups are 0..31");
        c.groups |= 1u << g;
      }
    } else if (key == "axis") {
      spec.shape.axis = parse_axis(v);
    } else {
      throw py::type_error("add_body() got an unexpected keyword argument '" + key + "'");
    }
  }
}

Joint& add_joint(Model& model, const std::string& name, RigidBody& parent, RigidBody& child,
                 const std::string& type, const py::kwargs& kw) {
  JointSpec spec;
  spec.name = name;
  spec.parent = &parent;
  spec.child = &child;
  spec.type = parse_joint_type(type);
  bool continuous = type == "continuous";
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "parent_pivot") {
      spec.parent_pivot = v.cast<Vec3>();
    } else if (key == "parent_axis") {
      spec.parent_axis = v.cast<Vec3>();
    } else if (key == "child_pivot") {
      spec.child_pivot = v.cast<Vec3>();
    } else if (key == "child_axis") {
      spec.child_axis = v.cast<Vec3>();
    } else if (key == "offset") {
      spec.offset = v.cast<double>();
    } else if (key == "child_offset") {
      spec.child_offset = v.cast<double>();
    } else if (key == "lower") {
      if (!v.is_none()) spec.lower = v.cast<double>();
    } else if (key == "upper") {
      if (!v.is_none()) spec.upper = v.cast<double>();
    } else if (key == "damping") {
      spec.damping = v.cast<double>();
    } else if (key == "stiffness") {
      spec.stiffness = v.cast<double>();
    } else if (key == "equilibrium") {
      spec.equilibrium = v.cast<double>();
    } else if (key == "max_motor_impulse") {
      spec.max_motor_impulse = v.cast<double>();
    } else if (key == "erp") {
      spec.erp = v.cast<double>();
    } else if (key == "cfm") {
      spec.cfm = v.cast<double>();
    } else if (key == "controller") {
      if (!v.is_none()) {
        // A declared controller drives efforts unless told otherwise, as in AMBF.
        JointController declared;
        declared.output = ControlOutput::kEffort;
        spec.controller = parse_controller(v.cast<py::dict>(), declared);
      }
    } else if (key == "passive") {
      spec.passive = v.cast<bool>();
    } else if (key == "ignore_inter_collision") {
      spec.ignore_inter_collision = v.cast<bool>();
    } else {
      throw py::type_error("add_joint() got an unexpected keyword argument '" + key + "'");
    }
  }
  if (continuous && (spec.lower || spec.upper)) {
    throw py::value_error("joint '" + name + "': a continuous joint has no limits");
  }
  return model.add_joint(spec);
}

void register_physics(py::module_& m,
                      py::class_<RigidBody, Object, std::shared_ptr<RigidBody>>& body,
                      py::class_<Joint, Object, std::shared_ptr<Joint>>& joint) {
  body.def_property_readonly("dynamic", &RigidBody::is_dynamic,
                             "moved by physics (mass > 0 and not kinematic)")
      .def_property(
          "kinematic", [](RigidBody& b) { return b.dynamics().kinematic; },
          &RigidBody::set_kinematic, "moved only by setting its pose")
      .def_property("linear_velocity", &RigidBody::linear_velocity, &RigidBody::set_linear_velocity,
                    "of the body origin, world frame, m/s")
      .def_property("angular_velocity", &RigidBody::angular_velocity,
                    &RigidBody::set_angular_velocity, "world frame, rad/s")
      .def_property(
          "force", [](RigidBody& b) { return Vec3(b.force()); }, &RigidBody::set_force,
          "N at the centre of mass, world frame, applied every step until changed")
      .def_property(
          "torque", [](RigidBody& b) { return Vec3(b.torque()); }, &RigidBody::set_torque,
          "N m, world frame, applied every step until changed")
      .def_property_readonly("inertia", &RigidBody::inertia,
                             "principal moments about the centre of mass, kg m^2")
      .def_property_readonly(
          "inertial_offset", [](RigidBody& b) { return Mat4(b.inertial_offset().matrix()); },
          "the centre-of-mass frame in the body frame")
      .def_property_readonly("center_of_mass", &RigidBody::center_of_mass, "world frame")
      .def_property(
          "friction", [](RigidBody& b) { return b.dynamics().static_friction; },
          [](RigidBody& b, double f) { b.set_friction(f, b.dynamics().rolling_friction); })
      .def_property(
          "rolling_friction", [](RigidBody& b) { return b.dynamics().rolling_friction; },
          [](RigidBody& b, double f) { b.set_friction(b.dynamics().static_friction, f); })
      .def_property(
          "restitution", [](RigidBody& b) { return b.dynamics().restitution; },
          &RigidBody::set_restitution)
      .def_property(
          "damping",
          [](RigidBody& b) {
            return py::make_tuple(b.dynamics().linear_damping, b.dynamics().angular_damping);
          },
          [](RigidBody& b, std::pair<double, double> d) { b.set_damping(d.first, d.second); },
          "(linear, angular), 0..1")
      .def_property_readonly("is_ghost", &is_ghost, "a ghost object (World.add_ghost)")
      .def_property_readonly(
          "overlapping",
          [](RigidBody& b) {
            py::list out;
            for (RigidBody* o : ghost_overlaps(b)) out.append(handle(o, b.world()));
            return out;
          },
          "a ghost's overlapping bodies after the last step (Bullet's narrow phase), in "
          "creation order; ValueError for a body that is not a ghost");

  joint.def_property_readonly("type", [](Joint& j) { return joint_type_name(j.type()); })
      .def_property_readonly("parent",
                             [](Joint& j) {
                               return std::shared_ptr<RigidBody>(
                                   j.world().simulator().shared_from_this(), &j.parent());
                             })
      .def_property_readonly("child",
                             [](Joint& j) {
                               return std::shared_ptr<RigidBody>(
                                   j.world().simulator().shared_from_this(), &j.child());
                             })
      .def_property_readonly("position", &Joint::position,
                             "rad or m; 0 where the parent's and child's joint frames coincide")
      .def_property_readonly("velocity", &Joint::velocity, "rad/s or m/s")
      .def_property_readonly("effort", &Joint::effort,
                             "effort applied in the last step (controller or command)")
      .def_property_readonly("passive", [](Joint& j) { return j.spec().passive; })
      .def_property_readonly("command",
                             [](Joint& j) {
                               switch (j.command()) {
                                 case Joint::Command::kPosition:
                                   return "position";
                                 case Joint::Command::kVelocity:
                                   return "velocity";
                                 case Joint::Command::kEffort:
                                   return "effort";
                                 case Joint::Command::kNone:
                                   break;
                               }
                               return "none";
                             })
      .def_property_readonly("command_value", &Joint::command_value)
      .def("set_position", &Joint::set_position, py::arg("target"),
           "drive to this position with the joint's controller")
      .def("set_velocity", &Joint::set_velocity, py::arg("target"),
           "drive at this velocity with the joint's motor")
      .def("set_effort", &Joint::set_effort, py::arg("effort"), "apply this effort every step")
      .def("release", &Joint::release, "stop commanding the joint")
      .def_property(
          "limits", [](Joint& j) { return py::make_tuple(j.spec().lower, j.spec().upper); },
          [](Joint& j, std::pair<std::optional<double>, std::optional<double>> l) {
            j.set_limits(l.first, l.second);
          },
          "(lower, upper), None where unlimited")
      .def_property(
          "damping", [](Joint& j) { return j.spec().damping; }, &Joint::set_damping)
      .def_property(
          "controller", [](Joint& j) { return controller_dict(j.spec().controller); },
          [](Joint& j, const py::dict& d) {
            j.set_controller(parse_controller(d, j.spec().controller));
          },
          "{p, i, d, output}; output 'effort' or 'velocity'; assigning updates the keys given")
      .def_property(
          "six_dof",
          [](Joint& j) -> py::object {
            const std::optional<SixDofAxes> a = six_dof_axes(j);
            if (!a) return py::none();
            py::dict d;
            d["lower"] = std::vector<std::optional<double>>(a->lower.begin(), a->lower.end());
            d["upper"] = std::vector<std::optional<double>>(a->upper.begin(), a->upper.end());
            d["stiffness"] = a->stiffness;
            d["damping"] = a->damping;
            d["equilibrium"] = a->equilibrium;
            return std::move(d);
          },
          [](Joint& j, const py::dict& d) {
            SixDofAxes a = six_dof_axes(j).value_or(SixDofAxes{});
            for (auto item : d) {
              const std::string key = py::str(item.first);
              if (key == "lower" || key == "upper") {
                const auto v = item.second.cast<std::vector<std::optional<double>>>();
                if (v.size() != 6) throw py::value_error("six_dof: '" + key + "' needs 6 values");
                auto& out = key == "lower" ? a.lower : a.upper;
                std::copy(v.begin(), v.end(), out.begin());
              } else if (key == "stiffness" || key == "damping" || key == "equilibrium") {
                const auto v = item.second.cast<std::vector<double>>();
                if (v.size() != 6) throw py::value_error("six_dof: '" + key + "' needs 6 values");
                auto& out = key == "stiffness" ? a.stiffness
                            : key == "damping" ? a.damping
                                               : a.equilibrium;
                std::copy(v.begin(), v.end(), out.begin());
              } else {
                throw py::value_error("six_dof: unknown key '" + key +
                                      "' (lower, upper, stiffness, damping, equilibrium)");
              }
            }
            set_six_dof_axes(j, a);
          },
          "a six dof (spring) joint's per-axis settings {lower, upper, stiffness, damping, "
          "equilibrium}, 6 values each (x, y, z translation, then x, y, z rotation; a limit "
          "None or lower > upper: free); None before any were set; assigning updates the keys "
          "given")
      .def_property_readonly(
          "six_dof_coordinates", [](Joint& j) { return six_dof_coordinates(j); },
          "a six dof (spring) joint's six coordinates now (m, rad)")
      .def("set_cone_twist_limits", &set_cone_twist_limits, py::arg("twist"), py::arg("swing_y"),
           py::arg("swing_z"), "a cone twist joint's twist (about its axis) and swing spans, rad");
}

}  // namespace ambfplus::bindings
