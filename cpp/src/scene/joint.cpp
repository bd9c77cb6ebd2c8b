#include "ambfplus/scene/joint.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"
#include "util/strings.h"

namespace ambfplus {

JointType parse_joint_type(const std::string& name) {
  const std::string n = to_lower(name);
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

Joint::Joint(Model& model, const JointSpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string who = "joint '" + spec.name + "': ";
  if (spec.parent == nullptr || spec.child == nullptr) {
    throw ArgumentError(who + "needs a parent and a child body");
  }
  if (spec.parent == spec.child) throw ArgumentError(who + "parent and child are the same");
  if (&spec.parent->world() != &model.world() || &spec.child->world() != &model.world()) {
    throw ArgumentError(who + "its bodies must be in the joint's world");
  }
  for (const Eigen::Vector3d* v : {&spec.parent_pivot, &spec.child_pivot}) {
    if (!v->allFinite()) throw ArgumentError(who + "pivots must be finite");
  }
  for (const Eigen::Vector3d* v : {&spec.parent_axis, &spec.child_axis}) {
    if (!v->allFinite() || v->norm() < 1e-12) {
      throw ArgumentError(who + "axes must be finite and non-zero");
    }
  }
  if (spec.lower && spec.upper && *spec.lower > *spec.upper) {
    throw ArgumentError(who + "lower limit above upper limit");
  }
  if (!(spec.damping >= 0) || !(spec.stiffness >= 0) || !(spec.max_motor_impulse >= 0)) {
    throw ArgumentError(who + "damping, stiffness and max motor impulse must be >= 0");
  }
}

void Joint::set_position(double target) {
  if (!std::isfinite(target)) throw ArgumentError("joint position must be finite");
  if (command_ != Command::kPosition) integral_ = 0;
  command_ = Command::kPosition;
  target_ = target;
}

void Joint::set_velocity(double target) {
  if (!std::isfinite(target)) throw ArgumentError("joint velocity must be finite");
  command_ = Command::kVelocity;
  target_ = target;
}

void Joint::set_effort(double effort) {
  if (!std::isfinite(effort)) throw ArgumentError("joint effort must be finite");
  command_ = Command::kEffort;
  target_ = effort;
}

void Joint::release() {
  command_ = Command::kNone;
  target_ = 0;
  integral_ = 0;
}

void Joint::set_controller(const JointController& controller) {
  if (!std::isfinite(controller.p) || !std::isfinite(controller.i) ||
      !std::isfinite(controller.d)) {
    throw ArgumentError("joint '" + name() + "': controller gains must be finite");
  }
  spec_.controller = controller;
  integral_ = 0;
}

void Joint::set_damping(double damping) {
  if (!(damping >= 0)) throw ArgumentError("joint damping must be >= 0");
  spec_.damping = damping;
}

Joint::~Joint() = default;

}  // namespace ambfplus
