// ProximitySensor's physics side: Bullet ray tests.

#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <limits>
#include <utility>
#include <vector>

#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/soft_body.h"
#include "ambfplus/scene/world.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace physics {
namespace {

// The nearest hit, leaving out one object and objects that collide with nothing.
struct NearestHit : btCollisionWorld::ClosestRayResultCallback {
  NearestHit(const btVector3& from, const btVector3& to, const btCollisionObject* ignore)
      : ClosestRayResultCallback(from, to), ignore_(ignore) {}
  bool needsCollision(btBroadphaseProxy* proxy) const override {
    if (!ClosestRayResultCallback::needsCollision(proxy)) return false;
    const auto* o = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    return o != ignore_ && o->hasContactResponse();
  }
  const btCollisionObject* ignore_;
};

// The convex pieces of a shape placed in the world (none for concave shapes).
void convex_pieces(const btCollisionShape* shape, const btTransform& t,
                   std::vector<std::pair<const btConvexShape*, btTransform>>& out) {
  if (shape->isConvex()) {
    out.emplace_back(static_cast<const btConvexShape*>(shape), t);
  } else if (shape->isCompound()) {
    const auto* compound = static_cast<const btCompoundShape*>(shape);
    for (int i = 0; i < compound->getNumChildShapes(); ++i) {
      convex_pieces(compound->getChildShape(i), t * compound->getChildTransform(i), out);
    }
  }
}

// Bullet casts rays against convex shapes until it is within a millimetre of them, so a hit can
// be that much short. From a little before it, this walks along the ray by the exact distance to
// the shape (sphere tracing, which cannot step through a surface) until it touches it. Triangle
// meshes and planes are hit exactly by Bullet and left as they are.
void refine_convex_hit(const btCollisionObject& object, const btVector3& from, const btVector3& to,
                       btScalar& fraction, btVector3& normal) {
  std::vector<std::pair<const btConvexShape*, btTransform>> pieces;
  convex_pieces(object.getCollisionShape(), object.getWorldTransform(), pieces);
  if (pieces.empty()) return;
  const btScalar length = (to - from).length();
  if (!(length > 0)) return;
  const btVector3 dir = (to - from) / length;
  constexpr btScalar kBackOff = 0.003, kTouch = 1e-6;
  btScalar t = btMax(btScalar(0), fraction * length - kBackOff);
  btVector3 n = normal;
  bool touched = false;
  for (int iteration = 0; iteration < 100 && !touched; ++iteration) {
    const btVector3 p = from + dir * t;
    btScalar d = std::numeric_limits<btScalar>::max();
    for (const auto& [shape, where] : pieces) {
      btGjkEpaSolver2::sResults r;
      const btScalar di = btGjkEpaSolver2::SignedDistance(p, 0, shape, where, r);
      if (di < d) {
        d = di;
        n = r.normal;
      }
    }
    if (d < 0) return;  // started inside (a ray from within a body): keep Bullet's answer
    touched = d < kTouch;
    t += d;
    if (t > length) return;
  }
  if (!touched) return;  // a grazing ray that did not settle: keep Bullet's answer
  fraction = t / length;
  // GJK's normal points from the shape towards the query point.
  if (n.length2() > 0 && n.dot(dir) < 0) normal = n.normalized();
}

}  // namespace

RayHit PhysicsWorld::ray_test(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                              const RigidBody* ignore) const {
  const btVector3 a = to_bullet(from), b = to_bullet(to);
  const btCollisionObject* skip =
      ignore != nullptr && body_of(*ignore) ? body_of(*ignore)->body.get() : nullptr;
  NearestHit callback(a, b, skip);
  world_->rayTest(a, b, callback);
  RayHit out;
  if (!callback.hasHit()) return out;
  btScalar fraction = callback.m_closestHitFraction;
  btVector3 normal = callback.m_hitNormalWorld;
  if (callback.m_collisionObject->getInternalType() == btCollisionObject::CO_RIGID_BODY) {
    refine_convex_hit(*callback.m_collisionObject, a, b, fraction, normal);
  }
  out.hit = true;
  out.fraction = fraction;
  out.point = to_eigen(a.lerp(b, fraction));
  const Eigen::Vector3d n = to_eigen(normal);
  out.normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
  const btCollisionObject* o = callback.m_collisionObject;
  if (o->getInternalType() == btCollisionObject::CO_RIGID_BODY) {
    out.body = static_cast<const Body*>(o->getUserPointer())->owner;
  } else if (o->getInternalType() == btCollisionObject::CO_SOFT_BODY) {
    out.soft_body = static_cast<SoftBody*>(o->getUserPointer());
    // The node nearest the hit point.
    const btSoftBody& sb = *static_cast<const btSoftBody*>(o);
    btScalar best = std::numeric_limits<btScalar>::max();
    for (int i = 0; i < sb.m_nodes.size(); ++i) {
      const btScalar d = (sb.m_nodes[i].m_x - callback.m_hitPointWorld).length2();
      if (d < best) {
        best = d;
        out.soft_body_node = i;
      }
    }
  }
  return out;
}

}  // namespace physics

ProximitySensor::~ProximitySensor() = default;

void ProximitySensor::update() {
  const Eigen::Isometry3d frame = parent().pose() * checked_pose(spec_.location);
  Object::set_pose(frame);
  const physics::PhysicsWorld& physics = physics::physics_of(*this);
  for (std::size_t i = 0; i < spec_.rays.size(); ++i) {
    const SensorRay& r = spec_.rays[i];
    const Eigen::Vector3d from = frame * r.offset;
    const Eigen::Vector3d to = frame * (r.offset + r.direction * spec_.range);
    const double length = (to - from).norm();
    const physics::RayHit h = physics.ray_test(from, to, spec_.parent);
    SensorHit& out = hits_[i];
    out.triggered = h.hit;
    out.fraction = h.hit ? h.fraction : 1.0;
    out.distance = out.fraction * length;
    out.point = h.hit ? h.point : to;
    out.normal = h.normal;
    out.body = h.body;
    out.soft_body = h.soft_body;
    out.soft_body_node = h.soft_body_node;
  }
}

}  // namespace ambfplus
