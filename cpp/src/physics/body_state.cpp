// RigidBody's physics side: what it asks of Bullet.

#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/world.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace {

void check_finite(const Eigen::Vector3d& v, const std::string& body, const char* what) {
  if (!v.allFinite()) throw ArgumentError("body '" + body + "': " + what + " must be finite");
}

}  // namespace

void RigidBody::set_pose(const Eigen::Isometry3d& pose) {
  Object::set_pose(pose);
  if (physics::body_of(*this) == nullptr) return;
  const btTransform t = physics::to_bullet(pose * physics::body_of(*this)->offset);
  btRigidBody& body = *physics::body_of(*this)->body;
  // Kinematic bodies move through their motion state, so Bullet sees their velocity.
  physics::body_of(*this)->motion->setWorldTransform(t);
  if (!dynamics_.kinematic) {
    body.setWorldTransform(t);
    body.setInterpolationWorldTransform(t);
    body.activate(true);
    // Ray tests see the body's new place before the next step.
    if (physics::body_of(*this)->world != nullptr)
      physics::body_of(*this)->world->updateSingleAabb(&body);
  }
}

void RigidBody::set_kinematic(bool kinematic) {
  if (kinematic == dynamics_.kinematic) return;
  if (!kinematic && shape_.kind == Shape::Kind::kPlane && dynamics_.mass > 0) {
    throw ArgumentError("body '" + name() + "': a plane cannot be dynamic");
  }
  dynamics_.kinematic = kinematic;
  if (physics::body_of(*this) != nullptr) {
    physics::physics_of(*this).refresh(*this);
    set_pose(pose());
  }
}

Eigen::Vector3d RigidBody::linear_velocity() const {
  const btRigidBody& b = *physics::body_of(*this)->body;
  const Eigen::Vector3d r = pose().translation() - physics::to_eigen(b.getCenterOfMassPosition());
  return physics::to_eigen(b.getVelocityInLocalPoint(physics::to_bullet(r)));
}

Eigen::Vector3d RigidBody::angular_velocity() const {
  return physics::to_eigen(physics::body_of(*this)->body->getAngularVelocity());
}

void RigidBody::set_linear_velocity(const Eigen::Vector3d& v) {
  check_finite(v, name(), "velocity");
  btRigidBody& b = *physics::body_of(*this)->body;
  // The centre of mass moves with v less the part the spin adds at the body origin.
  const Eigen::Vector3d r = pose().translation() - physics::to_eigen(b.getCenterOfMassPosition());
  const Eigen::Vector3d w = physics::to_eigen(b.getAngularVelocity());
  b.setLinearVelocity(physics::to_bullet(Eigen::Vector3d(v - w.cross(r))));
  b.activate(true);
}

void RigidBody::set_angular_velocity(const Eigen::Vector3d& w) {
  check_finite(w, name(), "angular velocity");
  const Eigen::Vector3d v = linear_velocity();
  physics::body_of(*this)->body->setAngularVelocity(physics::to_bullet(w));
  set_linear_velocity(v);
}

void RigidBody::set_force(const Eigen::Vector3d& f) {
  check_finite(f, name(), "force");
  force_ = f;
}

void RigidBody::set_torque(const Eigen::Vector3d& t) {
  check_finite(t, name(), "torque");
  torque_ = t;
}

Eigen::Vector3d RigidBody::inertia() const { return physics::body_of(*this)->inertia; }

Eigen::Isometry3d RigidBody::inertial_offset() const { return physics::body_of(*this)->offset; }

void RigidBody::set_friction(double static_friction, double rolling_friction) {
  if (!(static_friction >= 0) || !(rolling_friction >= 0)) {
    throw ArgumentError("body '" + name() + "': friction must be >= 0");
  }
  dynamics_.static_friction = static_friction;
  dynamics_.rolling_friction = rolling_friction;
  physics::body_of(*this)->body->setFriction(static_friction);
  physics::body_of(*this)->body->setRollingFriction(rolling_friction);
}

void RigidBody::set_restitution(double restitution) {
  if (!(restitution >= 0 && restitution <= 1)) {
    throw ArgumentError("body '" + name() + "': restitution must be in 0..1");
  }
  dynamics_.restitution = restitution;
  physics::body_of(*this)->body->setRestitution(restitution);
}

void RigidBody::set_damping(double linear, double angular) {
  if (!(linear >= 0 && linear <= 1) || !(angular >= 0 && angular <= 1)) {
    throw ArgumentError("body '" + name() + "': damping must be in 0..1");
  }
  dynamics_.linear_damping = linear;
  dynamics_.angular_damping = angular;
  physics::body_of(*this)->body->setDamping(linear, angular);
}

void RigidBody::ignore_collisions_with(RigidBody& other) {
  if (physics::body_of(*this) == nullptr || physics::body_of(other) == nullptr || &other == this)
    return;
  physics::body_of(*this)->body->setIgnoreCollisionCheck(physics::body_of(other)->body.get(), true);
  physics::body_of(other)->body->setIgnoreCollisionCheck(physics::body_of(*this)->body.get(), true);
}

}  // namespace ambfplus
