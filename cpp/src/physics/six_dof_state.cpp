// Six dof and cone twist joints' per-axis limits and springs, on their Bullet constraints.

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/six_dof.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace {

btGeneric6DofSpring2Constraint& six_dof_of(const Joint& joint) {
  if (joint.type() != JointType::kSixDof && joint.type() != JointType::kSixDofSpring) {
    throw ArgumentError("joint '" + joint.name() + "' is a " + joint_type_name(joint.type()) +
                        " joint, not a six dof or six dof spring joint");
  }
  const physics::Constraint* c = physics::constraint_of(joint);
  if (c == nullptr || !c->constraint) {
    throw StateError("joint '" + joint.name() + "' is not simulated");
  }
  return static_cast<btGeneric6DofSpring2Constraint&>(*c->constraint);
}

void check(const Joint& joint, bool ok, const std::string& what) {
  if (!ok) throw ArgumentError("joint '" + joint.name() + "': " + what);
}

}  // namespace

void set_six_dof_axes(Joint& joint, const SixDofAxes& axes) {
  btGeneric6DofSpring2Constraint& six = six_dof_of(joint);
  const char* names[6] = {"linear x",  "linear y",  "linear z",
                          "angular x", "angular y", "angular z"};
  for (int i = 0; i < 6; ++i) {
    const std::string axis = names[i];
    check(joint,
          (!axes.lower[i] || std::isfinite(*axes.lower[i])) &&
              (!axes.upper[i] || std::isfinite(*axes.upper[i])),
          axis + " limits must be finite");
    check(joint, std::isfinite(axes.stiffness[i]) && axes.stiffness[i] >= 0,
          axis + " stiffness must be finite and >= 0");
    check(joint, std::isfinite(axes.damping[i]) && axes.damping[i] >= 0,
          axis + " damping must be finite and >= 0");
    check(joint, std::isfinite(axes.equilibrium[i]), axis + " equilibrium point must be finite");
  }
  const bool springs = joint.type() == JointType::kSixDofSpring;
  for (int i = 0; i < 6; ++i) {
    // Both limits given: Bullet's range (lower > upper is free there); otherwise free.
    if (axes.lower[i] && axes.upper[i]) {
      six.setLimit(i, *axes.lower[i], *axes.upper[i]);
    } else {
      six.setLimit(i, 1.0, -1.0);
    }
    six.enableSpring(i, springs);
    if (springs) {
      six.setStiffness(i, axes.stiffness[i]);
      six.setDamping(i, axes.damping[i]);
      six.setEquilibriumPoint(i, axes.equilibrium[i]);
    }
  }
  physics::constraint_of(joint)->six_dof = axes;
  physics::body_of(joint.parent())->body->activate(true);
  physics::body_of(joint.child())->body->activate(true);
}

std::optional<SixDofAxes> six_dof_axes(const Joint& joint) {
  six_dof_of(joint);
  return physics::constraint_of(joint)->six_dof;
}

std::array<double, 6> six_dof_coordinates(const Joint& joint) {
  btGeneric6DofSpring2Constraint& six = six_dof_of(joint);
  six.calculateTransforms();
  return {six.getRelativePivotPosition(0),
          six.getRelativePivotPosition(1),
          six.getRelativePivotPosition(2),
          six.getAngle(0),
          six.getAngle(1),
          six.getAngle(2)};
}

void set_cone_twist_limits(Joint& joint, double twist, double swing_y, double swing_z) {
  if (joint.type() != JointType::kConeTwist) {
    throw ArgumentError("joint '" + joint.name() + "' is a " + joint_type_name(joint.type()) +
                        " joint, not a cone twist joint");
  }
  for (double v : {twist, swing_y, swing_z}) {
    check(joint, std::isfinite(v) && v >= 0, "cone twist limits must be finite and >= 0");
  }
  const physics::Constraint* c = physics::constraint_of(joint);
  if (c == nullptr || !c->constraint) {
    throw StateError("joint '" + joint.name() + "' is not simulated");
  }
  auto& cone = static_cast<btConeTwistConstraint&>(*c->constraint);
  // Bullet's indices: 3 the twist (about x), 4 the swing about y, 5 the swing about z.
  cone.setLimit(3, twist);
  cone.setLimit(4, swing_y);
  cone.setLimit(5, swing_z);
  physics::body_of(joint.parent())->body->activate(true);
  physics::body_of(joint.child())->body->activate(true);
}

}  // namespace ambfplus
