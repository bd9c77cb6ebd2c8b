// Ghost objects' physics side: a collision object outside the dynamics world, so it pushes
// nothing and rays miss it, tested against the world's bodies by Bullet's narrow phase.

#include <algorithm>

#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/model.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace physics {
namespace {

// Every rigid body whose shape penetrates the ghost's (Bullet also reports pairs closer than
// the contact threshold; those are near, not overlapping). Soft bodies are left to
// soft_body_inside: Bullet's soft-rigid algorithm makes no manifold points, it adds contacts to
// the soft body itself.
struct OverlapCollector : btCollisionWorld::ContactResultCallback {
  const btCollisionObject* ghost = nullptr;
  std::vector<Object*> found;

  bool needsCollision(btBroadphaseProxy* proxy) const override {
    const auto* other = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    return other->getInternalType() != btCollisionObject::CO_SOFT_BODY &&
           ContactResultCallback::needsCollision(proxy);
  }

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

// Whether point p (world) is inside shape at t: convex parts by GJK/EPA's signed distance,
// compounds part by part, planes by their side. false for concave meshes (no inside to test).
bool point_inside(const btCollisionShape* shape, const btTransform& t, const btVector3& p) {
  if (shape->isCompound()) {
    const auto* compound = static_cast<const btCompoundShape*>(shape);
    for (int i = 0; i < compound->getNumChildShapes(); ++i) {
      if (point_inside(compound->getChildShape(i), t * compound->getChildTransform(i), p)) {
        return true;
      }
    }
    return false;
  }
  if (shape->getShapeType() == STATIC_PLANE_PROXYTYPE) {
    const auto* plane = static_cast<const btStaticPlaneShape*>(shape);
    const btVector3 local = t.invXform(p);
    return plane->getPlaneNormal().dot(local) < plane->getPlaneConstant();
  }
  if (!shape->isConvex()) return false;
  btGjkEpaSolver2::sResults result;
  return btGjkEpaSolver2::SignedDistance(p, 0, static_cast<const btConvexShape*>(shape), t,
                                         result) < 0;
}

bool has_concave_part(const btCollisionShape* shape) {
  if (shape->isCompound()) {
    const auto* compound = static_cast<const btCompoundShape*>(shape);
    for (int i = 0; i < compound->getNumChildShapes(); ++i) {
      if (has_concave_part(compound->getChildShape(i))) return true;
    }
    return false;
  }
  return !shape->isConvex() && shape->getShapeType() != STATIC_PLANE_PROXYTYPE;
}

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
  // A soft body overlaps when one of its nodes is inside the ghost's shape.
  const btSoftBodyArray& softs = world_->getSoftBodyArray();
  if (softs.size() > 0) {
    const btCollisionShape* shape = b.ghost->getCollisionShape();
    const btTransform& t = b.ghost->getWorldTransform();
    if (has_concave_part(shape) && !b.warned_concave) {
      b.warned_concave = true;
      log(LogLevel::kWarning,
          "ghost '" + rb.name() +
              "' has a concave mesh shape: soft bodies overlapping it are not "
              "reported (rigid bodies are); give it a convex or primitive shape");
    }
    btVector3 lo, hi;
    shape->getAabb(t, lo, hi);
    for (int i = 0; i < softs.size(); ++i) {
      const btSoftBody* soft = softs[i];
      btVector3 soft_lo, soft_hi;
      soft->getAabb(soft_lo, soft_hi);
      if (!TestAabbAgainstAabb2(lo, hi, soft_lo, soft_hi)) continue;
      for (int n = 0; n < soft->m_nodes.size(); ++n) {
        if (point_inside(shape, t, soft->m_nodes[n].m_x)) {
          collector.found.push_back(static_cast<SoftBody*>(soft->getUserPointer()));
          break;
        }
      }
    }
  }
  // Creation order, whatever order the broadphase found them in.
  std::sort(collector.found.begin(), collector.found.end(),
            [](const Object* x, const Object* y) { return x->id() < y->id(); });
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

std::vector<Object*> ghost_overlaps(const RigidBody& ghost) {
  if (!is_ghost(ghost)) throw ArgumentError("body '" + ghost.name() + "' is not a ghost");
  return physics::body_of(ghost)->overlaps;
}

}  // namespace ambfplus
