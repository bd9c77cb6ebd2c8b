// ConstraintActuator's physics side: the Bullet constraint that holds a body.

#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"
#include "physics/physics_world.h"

namespace ambfplus {

void ConstraintActuator::actuate(RigidBody& body, const Eigen::Isometry3d& offset) {
  if (&body == &parent()) {
    throw ArgumentError("actuator '" + name() + "' cannot hold its own parent '" + body.name() +
                        "'");
  }
  if (&body.world() != &world()) {
    throw ArgumentError("actuator '" + name() + "': body '" + body.name() +
                        "' is in another world");
  }
  if (!body.is_dynamic()) {
    throw ArgumentError("actuator '" + name() + "': body '" + body.name() +
                        "' is static or kinematic; only bodies physics moves can be held");
  }
  if (!offset.matrix().allFinite()) {
    throw ArgumentError("actuator '" + name() + "': the offset must be finite");
  }
  if (body_ == &body) return;  // already held (as AMBF, a new offset does not re-grip)
  deactuate();

  physics::Body& pa = *physics::body_of(parent());
  physics::Body& pb = *physics::body_of(body);
  // The actuator frame on each body, in the body's centre-of-mass frame (Bullet's body frame).
  auto c = std::make_unique<physics::Constraint>();
  c->frame_a = physics::to_bullet(Eigen::Isometry3d(pa.offset.inverse() * location()));
  c->frame_b = physics::to_bullet(Eigen::Isometry3d(pb.offset.inverse() * offset));
  if (spec_.hold == ActuatorHold::kFixed) {
    c->constraint = std::make_unique<btFixedConstraint>(*pa.body, *pb.body, c->frame_a, c->frame_b);
  } else {
    auto point = std::make_unique<btPoint2PointConstraint>(
        *pa.body, *pb.body, c->frame_a.getOrigin(), c->frame_b.getOrigin());
    point->m_setting.m_impulseClamp = spec_.max_impulse;
    point->m_setting.m_tau = spec_.tau;
    c->constraint = std::move(point);
  }
  c->constraint->setUserConstraintPtr(c.get());
  c->actuator = this;
  btSoftRigidDynamicsWorld& bullet = physics::physics_of(*this).bullet();
  // The two bodies keep colliding, as in AMBF.
  bullet.addConstraint(c->constraint.get(), false);
  c->world = &bullet;
  pa.body->activate(true);
  pb.body->activate(true);
  set_physics_state(std::move(c));
  body_ = &body;
}

void ConstraintActuator::deactuate() {
  if (physics_state() == nullptr) return;
  RigidBody* held = body_;
  set_physics_state(nullptr);  // leaves Bullet
  body_ = nullptr;
  // A body held still may have gone to sleep; it falls now.
  if (held != nullptr && physics::body_of(*held) != nullptr)
    physics::body_of(*held)->body->activate(true);
}

}  // namespace ambfplus
