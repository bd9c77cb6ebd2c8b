// Joint's physics side: limits and state read from Bullet.

#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/scene/joint.h"
#include "physics/physics_world.h"

namespace ambfplus {

double Joint::position() const { return physics::PhysicsWorld::position(*this); }

double Joint::velocity() const { return physics::PhysicsWorld::velocity(*this); }

void Joint::set_limits(std::optional<double> lower, std::optional<double> upper) {
  if ((lower && !std::isfinite(*lower)) || (upper && !std::isfinite(*upper)) ||
      (lower && upper && *lower > *upper)) {
    throw ArgumentError("joint '" + name() + "': limits must be finite with lower <= upper");
  }
  spec_.lower = lower;
  spec_.upper = upper;
  if (physics::constraint_of(*this) == nullptr) return;
  btTypedConstraint* c = physics::constraint_of(*this)->constraint.get();
  const double big = 1e30;
  const double lo = lower.value_or(-big), hi = upper.value_or(big);
  const bool limited = lower || upper;
  switch (spec_.type) {
    case JointType::kRevolute: {
      // Bullet measures the hinge angle the other way round.
      auto* hinge = static_cast<btHingeConstraint*>(c);
      if (limited) {
        hinge->setLimit(-hi, -lo);
      } else {
        hinge->setLimit(1.0, -1.0);  // free
      }
      break;
    }
    case JointType::kPrismatic: {
      auto* slider = static_cast<btSliderConstraint*>(c);
      slider->setLowerLinLimit(limited ? lo : 1.0);
      slider->setUpperLinLimit(limited ? hi : -1.0);
      break;
    }
    case JointType::kLinearSpring:
    case JointType::kTorsionSpring:
    case JointType::kSixDofSpring: {
      auto* six = static_cast<btGeneric6DofSpring2Constraint*>(c);
      const int dof = spec_.type == JointType::kTorsionSpring ? 5 : 2;
      if (limited) {
        six->setLimit(dof, lo, hi);
      } else {
        six->setLimit(dof, 1.0, -1.0);
      }
      break;
    }
    case JointType::kConeTwist: {
      if (limited) {
        const double span = std::max(std::abs(lo), std::abs(hi));
        static_cast<btConeTwistConstraint*>(c)->setLimit(span, span, span);
      }
      break;
    }
    case JointType::kFixed:
    case JointType::kP2P:
    case JointType::kSixDof:
      break;
  }
}

}  // namespace ambfplus
