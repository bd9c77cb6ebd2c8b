// JointSpec: the names of its kinds, its checks and its keyword options.

#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/six_dof.h"
#include "util/strings.h"

namespace ambfplus {

JointType parse_joint_type(const std::string& name) {
  std::string n = to_lower(name);
  for (char& c : n) {
    if (c == '_') c = ' ';
  }
  if (n == "revolute" || n == "hinge" || n == "continuous") return JointType::kRevolute;
  if (n == "prismatic" || n == "slider") return JointType::kPrismatic;
  if (n == "fixed") return JointType::kFixed;
  if (n == "spring" || n == "linear spring") return JointType::kLinearSpring;
  if (n == "torsion spring" || n == "torsional spring" || n == "angular spring") {
    return JointType::kTorsionSpring;
  }
  if (n == "p2p") return JointType::kP2P;
  if (n == "cone twist") return JointType::kConeTwist;
  if (n == "six dof") return JointType::kSixDof;
  if (n == "six dof spring") return JointType::kSixDofSpring;
  throw ArgumentError(
      "unknown joint type '" + name +
      "': expected revolute, hinge, continuous, prismatic, slider, fixed, spring, linear spring, "
      "torsion spring, torsional spring, angular spring, p2p, cone twist, six dof or six dof "
      "spring");
}

const char* joint_type_name(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kFixed:
      return "fixed";
    case JointType::kLinearSpring:
      return "linear spring";
    case JointType::kTorsionSpring:
      return "torsion spring";
    case JointType::kP2P:
      return "p2p";
    case JointType::kConeTwist:
      return "cone twist";
    case JointType::kSixDof:
      return "six dof";
    case JointType::kSixDofSpring:
      return "six dof spring";
  }
  return "?";
}

ControlOutput parse_control_output(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "effort" || n == "force") return ControlOutput::kEffort;
  if (n == "velocity") return ControlOutput::kVelocity;
  throw ArgumentError("controller output must be 'effort' (or 'force') or 'velocity', got '" +
                      name + "'");
}

const char* control_output_name(ControlOutput output) {
  return output == ControlOutput::kEffort ? "effort" : "velocity";
}

void JointController::validate(const std::string& who) const {
  // A negative gain pushes away from the target: the joint runs off and the scene turns to NaN.
  if (!std::isfinite(p) || !std::isfinite(i) || !std::isfinite(d) || p < 0 || i < 0 || d < 0) {
    std::ostringstream got;
    got << "P " << p << ", I " << i << ", D " << d;
    throw ArgumentError(who + ": controller gains must be finite and >= 0, got " + got.str());
  }
}

void JointSpec::validate() const {
  const std::string who = "joint '" + name + "'";
  for (const Eigen::Vector3d* v : {&parent_pivot, &child_pivot}) {
    if (!v->allFinite()) throw ArgumentError(who + ": pivots must be finite");
  }
  for (const Eigen::Vector3d* v : {&parent_axis, &child_axis}) {
    if (!v->allFinite() || v->norm() < 1e-12) {
      throw ArgumentError(who + ": axes must be finite and non-zero");
    }
  }
  if ((lower && std::isnan(*lower)) || (upper && std::isnan(*upper))) {
    throw ArgumentError(who + ": limits must be numbers, not NaN");
  }
  if (lower && upper && *lower > *upper)
    throw ArgumentError(who + ": lower limit above upper limit");
  if (continuous && (lower || upper)) {
    throw ArgumentError(who + ": a continuous joint has no limits");
  }
  if (!(damping >= 0) || !(stiffness >= 0) || !(max_motor_impulse >= 0) ||
      !std::isfinite(damping) || !std::isfinite(stiffness) || !std::isfinite(max_motor_impulse)) {
    throw ArgumentError(who + ": damping, stiffness and max motor impulse must be >= 0");
  }
  for (double v : {offset, child_offset, equilibrium, erp, cfm}) {
    if (!std::isfinite(v)) {
      throw ArgumentError(who + ": offsets, equilibrium, erp and cfm must be finite");
    }
  }
  controller.validate(who);
}

const OptionTable<JointController>& joint_controller_options() {
  using C = JointController;
  using O = OptionTable<C>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<C> table(
      "controller",
      {
          O{"p", "float", "proportional gain", [](C& c, V v, K k) { c.p = v.number(k); }, {"P"}},
          O{"i", "float", "integral gain", [](C& c, V v, K k) { c.i = v.number(k); }, {"I"}},
          O{"d", "float", "derivative gain", [](C& c, V v, K k) { c.d = v.number(k); }, {"D"}},
          O{"output", "ControlOutput | str", "effort or velocity",
            [](C& c, V v, K k) { c.output = parse_control_output(v.text(k)); }},
      });
  return table;
}

namespace {

// Six values, one per axis of a six dof joint.
std::vector<OptionValue> six_values(const OptionValue& v, const std::string& key) {
  const std::vector<OptionValue>& values = v.list(key);
  if (values.size() != 6) {
    throw ArgumentError("'" + key + "' needs 6 values (x, y, z translation, then x, y, z " +
                        "rotation), not " + std::to_string(values.size()));
  }
  return values;
}

template <typename Array>
auto six_numbers(Array SixDofAxes::*field) {
  return [field](SixDofAxes& a, const OptionValue& v, const std::string& key) {
    const std::vector<OptionValue> values = six_values(v, key);
    for (std::size_t i = 0; i < 6; ++i) {
      if constexpr (std::is_same_v<Array, std::array<double, 6>>) {
        (a.*field)[i] = values[i].number(key);
      } else {
        (a.*field)[i] =
            values[i].is_none() ? std::nullopt : std::optional<double>(values[i].number(key));
      }
    }
  };
}

}  // namespace

const OptionTable<SixDofAxes>& six_dof_options() {
  using O = OptionTable<SixDofAxes>::Option;
  using Limits = std::array<std::optional<double>, 6>;
  using Values = std::array<double, 6>;
  static const OptionTable<SixDofAxes> table(
      "six_dof", {
                     O{"lower", "list[float | None]", "lower limits, m or rad (None: free)",
                       six_numbers<Limits>(&SixDofAxes::lower)},
                     O{"upper", "list[float | None]", "upper limits, m or rad (None: free)",
                       six_numbers<Limits>(&SixDofAxes::upper)},
                     O{"stiffness", "list[float]", "springs' stiffness, N/m or N m/rad",
                       six_numbers<Values>(&SixDofAxes::stiffness)},
                     O{"damping", "list[float]", "springs' damping, N s/m or N m s/rad",
                       six_numbers<Values>(&SixDofAxes::damping)},
                     O{"equilibrium", "list[float]", "springs' rest positions, m or rad",
                       six_numbers<Values>(&SixDofAxes::equilibrium)},
                 });
  return table;
}

const OptionTable<JointSpec>& joint_options() {
  using S = JointSpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "add_joint()", {
                         O{"type", "JointType | str", "revolute, prismatic, fixed, spring, ...",
                           [](S& s, V v, K k) {
                             s.type = parse_joint_type(v.text(k));
                             s.continuous = to_lower(v.text(k)) == "continuous";
                           }},
                         O{"parent_pivot", "tuple[float, float, float]", "in the parent's frame, m",
                           [](S& s, V v, K k) { s.parent_pivot = v.vector3(k); }},
                         O{"parent_axis", "tuple[float, float, float]", "in the parent's frame",
                           [](S& s, V v, K k) { s.parent_axis = v.vector3(k); }},
                         O{"child_pivot", "tuple[float, float, float]", "in the child's frame, m",
                           [](S& s, V v, K k) { s.child_pivot = v.vector3(k); }},
                         O{"child_axis", "tuple[float, float, float]", "in the child's frame",
                           [](S& s, V v, K k) { s.child_axis = v.vector3(k); }},
                         O{"offset", "float", "the parent frame's turn about the axis, rad",
                           [](S& s, V v, K k) { s.offset = v.number(k); }},
                         O{"child_offset", "float", "the child frame's turn about the axis, rad",
                           [](S& s, V v, K k) { s.child_offset = v.number(k); }},
                         O{"lower", "float | None", "limit, rad or m",
                           [](S& s, V v, K k) { s.lower = v.number(k); }},
                         O{"upper", "float | None", "limit, rad or m",
                           [](S& s, V v, K k) { s.upper = v.number(k); }},
                         O{"damping", "float", "N m s/rad or N s/m",
                           [](S& s, V v, K k) { s.damping = v.number(k); }},
                         O{"stiffness", "float", "springs: N m/rad or N/m",
                           [](S& s, V v, K k) { s.stiffness = v.number(k); }},
                         O{"equilibrium", "float", "springs: rest position",
                           [](S& s, V v, K k) { s.equilibrium = v.number(k); }},
                         O{"max_motor_impulse", "float", "N m s (or N s) per step",
                           [](S& s, V v, K k) { s.max_motor_impulse = v.number(k); }},
                         O{"erp", "float", "", [](S& s, V v, K k) { s.erp = v.number(k); }},
                         O{"cfm", "float", "", [](S& s, V v, K k) { s.cfm = v.number(k); }},
                         O{"controller", "dict[str, Any] | None", "{p, i, d, output}",
                           [](S& s, V v, K k) {
                             // A declared controller drives efforts unless told otherwise, as in
                             // AMBF.
                             JointController declared;
                             declared.output = ControlOutput::kEffort;
                             joint_controller_options().apply(declared, v.map(k));
                             s.controller = declared;
                           }},
                         O{"passive", "bool", "left out of its root body's joints, not controlled",
                           [](S& s, V v, K k) { s.passive = v.boolean(k); }},
                         O{"ignore_inter_collision",
                           "bool",
                           "parent and child do not collide",
                           [](S& s, V v, K k) { s.ignore_inter_collision = v.boolean(k); },
                           {"ignore inter-collision"}},
                     });
  return table;
}

}  // namespace ambfplus
