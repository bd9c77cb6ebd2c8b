// Ghost objects' physics side: a collision object outside the dynamics world, so it pushes
// nothing and rays miss it, tested against the world's bodies by Bullet's narrow phase.

#include <algorithm>

#include "ambfplus/errors.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/model.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace physics {
namespace {

// Every rigid body whose shape penetrates the ghost's (Bullet also reports pairs closer than
// the contact threshold; those are near, not overlapping).
struct OverlapCollector : btCollisionWorld::ContactResultCallback {
  const btCollisionObject* ghost = nullptr;
  std::vector<RigidBody*> found;

  btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* a, int, int,
                           const btCollisionObjectWrapper* b, int, int) override {
    if (point.getDistance() > 0) return 0;
    const btCollisionObject* other =
        a->getCollisionObject() == ghost ? b->getCollisionObject() : a->getCollisionObject();
    if (other->getInternalType() != btCollisionObject::CO_RIGID_BODY) return 0;
    RigidBody* owner = static_cast<const Body*>(other->getUserPointer())->owner;
    if (owner != nullptr && std::find(found.begin(), found.end(), owner) == found.end()) {
      found.push_back(owner);
    }
    return 0;
  }
};

}  // namespace

void PhysicsWorld::make_ghost(RigidBody& rb) {
  Body& b = *body_of(rb);
  if (b.world != nullptr) {
    world_->removeRigidBody(b.body.get());
    b.world = nullptr;
  }
  b.ghost = std::make_unique<btCollisionObject>();
  b.ghost->setCollisionShape(b.body->getCollisionShape());
  b.ghost->setCollisionFlags(btCollisionObject::CF_NO_CONTACT_RESPONSE);
  b.ghost->setUserPointer(&b);
  bodies_.erase(std::remove(bodies_.begin(), bodies_.end(), &rb), bodies_.end());
  ghosts_.push_back(&rb);
  update_ghost(rb);
}

void PhysicsWorld::update_ghost(RigidBody& rb) {
  Body& b = *body_of(rb);
  b.ghost->setWorldTransform(to_bullet(rb.pose() * b.offset));
  OverlapCollector collector;
  collector.ghost = b.ghost.get();
  world_->contactTest(b.ghost.get(), collector);
  // Creation order, whatever order the broadphase found them in.
  std::sort(collector.found.begin(), collector.found.end(),
            [](const RigidBody* x, const RigidBody* y) { return x->id() < y->id(); });
  b.overlaps = std::move(collector.found);
}

}  // namespace physics

RigidBody& add_ghost(Model& model, RigidBodySpec spec) {
  spec.dynamics.mass = 0;
  spec.dynamics.kinematic = false;
  spec.collision.enabled = true;  // its shape is what overlaps are tested against
  RigidBody& body = model.add_body(spec);
  physics::physics_of(body).make_ghost(body);
  return body;
}

bool is_ghost(const RigidBody& body) {
  const physics::Body* b = physics::body_of(body);
  return b != nullptr && b->ghost != nullptr;
}

std::vector<RigidBody*> ghost_overlaps(const RigidBody& ghost) {
  if (!is_ghost(ghost)) throw ArgumentError("body '" + ghost.name() + "' is not a ghost");
  return physics::body_of(ghost)->overlaps;
}

}  // namespace ambfplus
