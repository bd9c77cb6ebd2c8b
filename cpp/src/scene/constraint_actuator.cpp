// ConstraintActuator's scene side: checking the spec, following the parent.

#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

ConstraintActuator::ConstraintActuator(Model& model, const ConstraintActuatorSpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string& name = spec.name;
  if (spec_.parent == nullptr) {
    throw ArgumentError("actuator '" + name + "' needs a parent body");
  }
  if (&spec_.parent->world() != &model.world()) {
    throw ArgumentError("actuator '" + name + "': its parent '" + spec_.parent->name() +
                        "' is in another world");
  }
  spec_.validate();
  update();
}

Eigen::Isometry3d ConstraintActuator::location() const { return checked_pose(spec_.location); }

void ConstraintActuator::set_pose(const Eigen::Isometry3d& pose) {
  if (is_actuated()) {
    throw StateError("actuator '" + name() +
                     "' holds a body: deactuate it before moving the actuator");
  }
  spec_.location = (parent().pose().inverse() * pose).matrix();
  Object::set_pose(pose);
}

void ConstraintActuator::actuate(RigidBody& body) {
  // Where the actuator frame is on the body now: the body is held as it is.
  actuate(body, body.pose().inverse() * parent().pose() * location());
}

void ConstraintActuator::update() { Object::set_pose(parent().pose() * location()); }

ConstraintActuator::~ConstraintActuator() = default;

}  // namespace ambfplus
