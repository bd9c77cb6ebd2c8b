#include "ambfplus/scene/joint.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

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
  spec.validate();
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
  controller.validate("joint '" + name() + "'");
  spec_.controller = controller;
  integral_ = 0;
}

void Joint::set_damping(double damping) {
  if (!(damping >= 0)) throw ArgumentError("joint damping must be >= 0");
  spec_.damping = damping;
}

Joint::~Joint() = default;

}  // namespace ambfplus
