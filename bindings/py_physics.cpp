// The physical objects of ambfplus/scene: RigidBody, Joint, SoftBody, ProximitySensor and
// ConstraintActuator, with the kinds they take (ShapeKind, Axis, MeshCollision, JointType,
// ControlOutput, ActuatorHold). Every method of these classes is here.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/soft_body.h"
#include "bindings.h"
#include "enums.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat4 = Eigen::Matrix4d;

using BodyClass = py::class_<RigidBody, Object, std::shared_ptr<RigidBody>>;
using JointClass = py::class_<Joint, Object, std::shared_ptr<Joint>>;
using SoftClass = py::class_<SoftBody, Object, std::shared_ptr<SoftBody>>;
using SensorClass = py::class_<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>;
using ActuatorClass = py::class_<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>;

py::dict controller_dict(const JointController& c) {
  py::dict d;
  d["p"] = c.p;
  d["i"] = c.i;
  d["d"] = c.d;
  d["output"] = control_output_name(c.output);
  return d;
}

// A read-only (rows, 3) NumPy view of `data`, kept alive by `owner`.
template <typename T>
py::array rows_view(py::object owner, const T* data, std::size_t rows) {
  const auto s = static_cast<py::ssize_t>(sizeof(T));
  return readonly(py::array(py::dtype::of<T>(), {static_cast<py::ssize_t>(rows), py::ssize_t(3)},
                            {3 * s, s}, data, owner));
}

py::array_t<double> rows_copy(const std::vector<double>& xyz) {
  py::array_t<double> out({static_cast<py::ssize_t>(xyz.size() / 3), py::ssize_t(3)});
  std::copy(xyz.begin(), xyz.end(), out.mutable_data());
  return out;
}

// A node index list: ints in range (OutOfRange otherwise).
std::vector<int> node_list(const SoftBody& s, const std::vector<int>& nodes) {
  const int count = static_cast<int>(s.node_count());
  for (int n : nodes) {
    if (n < 0 || n >= count) {
      throw OutOfRange("soft body '" + s.name() + "' has nodes 0.." + std::to_string(count - 1) +
                       ", not " + std::to_string(n));
    }
  }
  return nodes;
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

void define_body(BodyClass& body) {
  body.def_property_readonly("shape", [](RigidBody& b) { return shape_kind_name(b.shape().kind); })
      .def_property_readonly("mass", &RigidBody::mass)
      .def_property_readonly("size", [](RigidBody& b) { return Vec3(b.shape().size); })
      .def_property_readonly("radius", [](RigidBody& b) { return b.shape().radius; })
      .def_property_readonly("height", [](RigidBody& b) { return b.shape().height; })
      .def_property_readonly("mesh", [](RigidBody& b) { return b.shape().mesh; })
      .def_property(
          "color", [](RigidBody& b) { return b.material().color; },
          [](RigidBody& b, const py::object& c) {
            Material m = b.material();
            m.color = to_option(c).rgba("color");
            b.set_material(m);
          },
          "RGBA in 0..1")
      .def_property(
          "shader", [](RigidBody& b) { return from_shader(b.material().shader); },
          [](RigidBody& b, const py::object& v) {
            Material m = b.material();
            m.shader = to_shader(v, "shader");
            b.set_material(m);
          },
          "the body's own shader (AMBF's body `shaders`): None (its model's), 'builtin' (the "
          "engine's own), or (vertex_path, fragment_path); it colours the rgb image only")
      .def_property_readonly("dynamic", &RigidBody::is_dynamic,
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
      .def_property_readonly(
          "joints",
          [](RigidBody& b) {
            py::list out;
            for (Joint* j : b.world().descendant_joints(b)) out.append(to_python(j));
            return out;
          },
          "The joints below this body in AMBF's order (every joint reachable from it, creation "
          "order, passive ones left out): the order of a root body's joint positions.")
      .def_property_readonly(
          "collision_mesh", [](RigidBody& b) { return b.collision().mesh; },
          "the separate collision mesh file, or '' (the visual mesh collides)")
      .def_property_readonly(
          "collision_shapes",
          [](RigidBody& b) {
            py::list out;
            for (const auto& [shape, pose] : b.collision().shapes) {
              out.append(py::make_tuple(shape_kind_name(shape.kind), Mat4(pose)));
            }
            return out;
          },
          "the primitive collision parts as (shape, 4x4 pose in the body frame)")
      .def_property_readonly("is_ghost", &is_ghost, "a ghost object (World.add_ghost)")
      .def_property_readonly(
          "overlapping",
          [](RigidBody& b) {
            py::list out;
            for (Object* o : ghost_overlaps(b)) out.append(handle(o, b.world()));
            return out;
          },
          "a ghost's overlapping bodies after the last step, in creation order: rigid bodies "
          "(Bullet's narrow phase) and soft bodies with a node inside its convex parts; "
          "ValueError for a body that is not a ghost");
}

void define_joint(JointClass& joint) {
  joint.def_property_readonly("type", [](Joint& j) { return joint_type_name(j.type()); })
      .def_property_readonly("parent", [](Joint& j) { return handle(&j.parent(), j.world()); })
      .def_property_readonly("child", [](Joint& j) { return handle(&j.child(), j.world()); })
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
            JointController c = j.spec().controller;
            joint_controller_options().apply(c, to_options(d));
            j.set_controller(c);
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
            six_dof_options().apply(a, to_options(d));
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
           py::arg("swing_z"), "a cone twist joint's twist (about its axis) and swing spans, rad")
      .def_property_readonly(
          "parent_pivot", [](Joint& j) { return j.spec().parent_pivot; },
          "pivot in the parent body's frame, m")
      .def_property_readonly(
          "child_pivot", [](Joint& j) { return j.spec().child_pivot; },
          "pivot in the child body's frame, m")
      .def_property_readonly("parent_axis", [](Joint& j) { return j.spec().parent_axis; })
      .def_property_readonly("child_axis", [](Joint& j) { return j.spec().child_axis; })
      .def_property_readonly("offset", [](Joint& j) { return j.spec().offset; })
      .def_property_readonly("child_offset", [](Joint& j) { return j.spec().child_offset; })
      .def_property_readonly(
          "anchors",
          [](Joint& j) {
            const Vec3 a = j.parent().pose() * j.spec().parent_pivot;
            const Vec3 b = j.child().pose() * j.spec().child_pivot;
            return py::make_tuple(a, b);
          },
          "the pivot on the parent and on the child, world frame: the joint holds them "
          "together");
}

void define_soft_body(SoftClass& soft) {
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
          [](SoftBody& s, const std::vector<int>& nodes, const Eigen::MatrixX3d& positions) {
            const std::vector<int> list = node_list(s, nodes);
            if (static_cast<Eigen::Index>(list.size()) != positions.rows()) {
              throw ArgumentError("set_node_positions: " + std::to_string(list.size()) +
                                  " nodes but " + std::to_string(positions.rows()) + " positions");
            }
            for (std::size_t i = 0; i < list.size(); ++i) {
              s.set_node_position(list[i], positions.row(static_cast<Eigen::Index>(i)));
            }
          },
          py::arg("nodes"), py::arg("positions"),
          "Moves nodes (indices) to positions ((K, 3), world frame) at once.")
      .def(
          "fix_nodes",
          [](SoftBody& s, const std::vector<int>& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, true);
          },
          py::arg("nodes"), "Pins nodes (indices) where they are.")
      .def(
          "release_nodes",
          [](SoftBody& s, const std::vector<int>& nodes) {
            for (int n : node_list(s, nodes)) s.set_node_fixed(n, false);
          },
          py::arg("nodes"), "Lets pinned nodes move again.")
      .def_property_readonly("fixed_nodes", &SoftBody::fixed_nodes, "pinned node indices")
      .def_property(
          "color", [](SoftBody& s) { return s.material().color; },
          [](SoftBody& s, const py::object& c) {
            Material mat = s.material();
            mat.color = to_option(c).rgba("color");
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
}

void define_sensor(SensorClass& sensor) {
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
            for (std::size_t i = 0; i < s.ray_count(); ++i) {
              out.mutable_at(i) = s.hits()[i].distance;
            }
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
}

void define_actuator(ActuatorClass& actuator) {
  actuator
      .def_property_readonly("parent", [](ConstraintActuator& a) { return handle(&a.parent()); })
      .def_property_readonly(
          "location", [](ConstraintActuator& a) { return Mat4(a.location().matrix()); },
          "4x4 actuator frame in the parent's frame")
      .def_property_readonly("max_impulse",
                             [](ConstraintActuator& a) { return a.spec().max_impulse; })
      .def_property_readonly("tau", [](ConstraintActuator& a) { return a.spec().tau; })
      .def_property_readonly(
          "hold", [](ConstraintActuator& a) { return actuator_hold_name(a.spec().hold); })
      .def(
          "actuate",
          [](ConstraintActuator& a, RigidBody& body, const py::object& offset) {
            if (offset.is_none()) {
              a.actuate(body);
              return;
            }
            const py::array arr = py::array::ensure(offset);
            if (arr && arr.ndim() == 2) {
              a.actuate(body, checked_pose(offset.cast<Mat4>(), a, "offset"));
            } else {
              Eigen::Isometry3d o = Eigen::Isometry3d::Identity();
              o.translation() = to_option(offset).vector3("offset");
              a.actuate(body, o);
            }
          },
          py::arg("body"), py::arg("offset") = py::none(),
          "Holds body: where it is now, or with the actuator at offset in the body's frame (a "
          "point, or a 4x4 frame), pulling it there. A body already held stays held.")
      .def("deactuate", &ConstraintActuator::deactuate, "Releases the body held.")
      .def("is_actuated", &ConstraintActuator::is_actuated, "Whether a body is held.")
      .def_property_readonly(
          "actuated_body",
          [](ConstraintActuator& a) -> py::object {
            return a.actuated_body() ? py::cast(handle(a.actuated_body())) : py::none();
          },
          "the body held, or None");
}

}  // namespace

void declare_physics(py::module_& m) {
  declare_enum<Shape::Kind>(m, "ShapeKind", "A rigid body's geometry.",
                            {{"box", Shape::Kind::kBox},
                             {"sphere", Shape::Kind::kSphere},
                             {"cylinder", Shape::Kind::kCylinder},
                             {"capsule", Shape::Kind::kCapsule},
                             {"cone", Shape::Kind::kCone},
                             {"plane", Shape::Kind::kPlane},
                             {"mesh", Shape::Kind::kMesh},
                             {"none", Shape::Kind::kNone}},
                            &parse_shape_kind);
  declare_enum<Axis>(m, "Axis", "A body axis (cylinders, capsules and cones run along one).",
                     {{"x", Axis::kX}, {"y", Axis::kY}, {"z", Axis::kZ}}, &parse_axis);
  declare_enum<MeshCollision>(m, "MeshCollision",
                              "How a body's collision shape is made from a mesh.",
                              {{"concave", MeshCollision::kConcave},
                               {"convex_mesh", MeshCollision::kConvexMesh},
                               {"convex_hull", MeshCollision::kConvexHull},
                               {"point_cloud", MeshCollision::kPointCloud}},
                              &parse_mesh_collision);
  declare_enum<JointType>(m, "JointType", "How a joint lets its child move.",
                          {{"revolute", JointType::kRevolute},
                           {"prismatic", JointType::kPrismatic},
                           {"fixed", JointType::kFixed},
                           {"linear_spring", JointType::kLinearSpring},
                           {"torsion_spring", JointType::kTorsionSpring},
                           {"p2p", JointType::kP2P},
                           {"cone_twist", JointType::kConeTwist},
                           {"six_dof", JointType::kSixDof},
                           {"six_dof_spring", JointType::kSixDofSpring}},
                          &parse_joint_type);
  declare_enum<ControlOutput>(
      m, "ControlOutput", "What a joint controller drives.",
      {{"effort", ControlOutput::kEffort}, {"velocity", ControlOutput::kVelocity}},
      &parse_control_output);
  declare_enum<ActuatorHold>(m, "ActuatorHold", "How a constraint actuator holds a body.",
                             {{"fixed", ActuatorHold::kFixed}, {"point", ActuatorHold::kPoint}},
                             &parse_actuator_hold);
  BodyClass(m, "RigidBody", "A rigid body: a shape with mass and a material.");
  JointClass(m, "Joint", "A joint between two bodies, with a controller and limits.");
  SoftClass(m, "SoftBody",
            "A deformable body: Bullet nodes at a mesh's vertices, links along its edges.");
  SensorClass(m, "ProximitySensor", "Rays fixed to a body reporting the nearest body along each.");
  ActuatorClass(m, "ConstraintActuator", "Holds a body to its parent body on request (a grasp).");
}

void define_physics(py::module_& m) {
  auto body = bound<RigidBody, Object, std::shared_ptr<RigidBody>>(m, "RigidBody");
  define_body(body);
  auto joint = bound<Joint, Object, std::shared_ptr<Joint>>(m, "Joint");
  define_joint(joint);
  auto soft = bound<SoftBody, Object, std::shared_ptr<SoftBody>>(m, "SoftBody");
  define_soft_body(soft);
  auto sensor =
      bound<ProximitySensor, Object, std::shared_ptr<ProximitySensor>>(m, "ProximitySensor");
  define_sensor(sensor);
  auto actuator = bound<ConstraintActuator, Object, std::shared_ptr<ConstraintActuator>>(
      m, "ConstraintActuator");
  define_actuator(actuator);
}

}  // namespace ambfplus::bindings
