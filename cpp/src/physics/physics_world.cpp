#include "physics/physics_world.h"

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/soft_body.h"
#include "ambfplus/scene/world.h"
#include "physics/shapes.h"

namespace ambfplus {
namespace physics {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Bodies collide when they share a collision group or when either is in none (and Bullet's own
// static/dynamic filtering allows it).
struct GroupFilter : btOverlapFilterCallback {
  bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
    if ((a->m_collisionFilterGroup & b->m_collisionFilterMask) == 0 ||
        (b->m_collisionFilterGroup & a->m_collisionFilterMask) == 0) {
      return false;
    }
    const auto* oa = static_cast<const btCollisionObject*>(a->m_clientObject);
    const auto* ob = static_cast<const btCollisionObject*>(b->m_clientObject);
    // Only rigid bodies carry a Body (soft bodies are in no group).
    const auto* ba = oa && oa->getInternalType() == btCollisionObject::CO_RIGID_BODY
                         ? static_cast<const Body*>(oa->getUserPointer())
                         : nullptr;
    const auto* bb = ob && ob->getInternalType() == btCollisionObject::CO_RIGID_BODY
                         ? static_cast<const Body*>(ob->getUserPointer())
                         : nullptr;
    if (ba == nullptr || bb == nullptr || ba->groups == 0 || bb->groups == 0) return true;
    return (ba->groups & bb->groups) != 0;
  }
};

// The joint frame on a body, in its centre-of-mass frame: `default_axis` turned onto `axis`,
// then turned by `turn` about it, at `pivot` (body frame).
btTransform joint_frame(const Eigen::Vector3d& pivot, const Eigen::Vector3d& axis, double turn,
                        const Eigen::Vector3d& default_axis, const Eigen::Isometry3d& offset) {
  const Eigen::Vector3d a = axis.normalized();
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = (Eigen::AngleAxisd(turn, a) * Eigen::Quaterniond::FromTwoVectors(default_axis, a))
                   .toRotationMatrix();
  f.translation() = pivot;
  return to_bullet(offset.inverse() * f);
}

// The axis a joint moves about or along: x for sliders and cone twists (Bullet's), z otherwise.
Eigen::Vector3d default_axis(JointType type) {
  return type == JointType::kPrismatic || type == JointType::kConeTwist ? Eigen::Vector3d::UnitX()
                                                                        : Eigen::Vector3d::UnitZ();
}

bool rotates(JointType type) {
  return type == JointType::kRevolute || type == JointType::kTorsionSpring;
}
bool slides(JointType type) {
  return type == JointType::kPrismatic || type == JointType::kLinearSpring ||
         type == JointType::kSixDofSpring;
}

// World frames of a joint on its parent and its child.
void joint_frames(const Joint& joint, btTransform& a, btTransform& b) {
  const Constraint& c = *constraint_of(joint);
  a = body_of(joint.parent())->body->getWorldTransform() * c.frame_a;
  b = body_of(joint.child())->body->getWorldTransform() * c.frame_b;
}

double wrap(double angle) { return std::remainder(angle, 2 * kPi); }

}  // namespace

Eigen::Isometry3d to_eigen(const btTransform& t) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  const btMatrix3x3& r = t.getBasis();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out.linear()(i, j) = r[i][j];
  }
  out.translation() = to_eigen(t.getOrigin());
  return out;
}

btTransform to_bullet(const Eigen::Isometry3d& t) {
  const Eigen::Matrix3d& r = t.linear();
  btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1),
                    r(2, 2));
  return btTransform(basis, to_bullet(Eigen::Vector3d(t.translation())));
}

Body::~Body() {
  if (world != nullptr && body) world->removeRigidBody(body.get());
}

Constraint::~Constraint() {
  if (world != nullptr && constraint) world->removeConstraint(constraint.get());
}

PhysicsWorld::PhysicsWorld() {
  config_ = std::make_unique<btSoftBodyRigidBodyCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  btGImpactCollisionAlgorithm::registerAlgorithm(dispatcher_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  world_ = std::make_unique<btSoftRigidDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                      solver_.get(), config_.get());
  filter_ = std::make_unique<GroupFilter>();
  world_->getPairCache()->setOverlapFilterCallback(filter_.get());
  set_gravity(Eigen::Vector3d(0, 0, -9.8));
}

PhysicsWorld::~PhysicsWorld() { detach_all(); }

std::unique_ptr<Physics> make_physics(World&) { return std::make_unique<PhysicsWorld>(); }

Physics& physics_of(const World& world) {
  if (auto* physics = world.find_system<Physics>()) return *physics;
  throw StateError("world '" + world.name() + "' has no physics (make it with the engine)");
}

PhysicsWorld& physics_of(const Object& object) {
  return static_cast<PhysicsWorld&>(physics_of(object.world()));
}

void PhysicsWorld::object_added(Object& object) {
  switch (object.kind()) {
    case ObjectKind::kRigidBody:
      add(static_cast<RigidBody&>(object));
      break;
    case ObjectKind::kJoint:
      add(static_cast<Joint&>(object));
      break;
    case ObjectKind::kSoftBody:
      add(static_cast<SoftBody&>(object));
      break;
    case ObjectKind::kActuator:
      actuators_.push_back(static_cast<ConstraintActuator*>(&object));
      break;
    case ObjectKind::kSensor:
      sensors_.push_back(static_cast<ProximitySensor*>(&object));
      // Readings from the start, before the first step.
      static_cast<ProximitySensor&>(object).update();
      break;
    default:
      break;
  }
}

void PhysicsWorld::object_removed(Object& object) {
  switch (object.kind()) {
    case ObjectKind::kRigidBody:
      remove(static_cast<RigidBody&>(object));
      break;
    case ObjectKind::kJoint:
      remove(static_cast<Joint&>(object));
      break;
    case ObjectKind::kSoftBody: {
      Soft* soft = soft_of(static_cast<SoftBody&>(object));
      if (soft != nullptr && soft->world != nullptr) {
        soft->world->removeSoftBody(soft->body.get());
        soft->world = nullptr;
      }
      for (RigidBody* g : ghosts_) {
        std::vector<Object*>& o = body_of(*g)->overlaps;
        o.erase(std::remove(o.begin(), o.end(), &object), o.end());
      }
      break;
    }
    case ObjectKind::kActuator: {
      auto* actuator = static_cast<ConstraintActuator*>(&object);
      actuator->deactuate();
      actuators_.erase(std::remove(actuators_.begin(), actuators_.end(), actuator),
                       actuators_.end());
      break;
    }
    case ObjectKind::kSensor:
      sensors_.erase(std::remove(sensors_.begin(), sensors_.end(), &object), sensors_.end());
      break;
    default:
      break;
  }
}

void PhysicsWorld::run(StepStage stage, const StepContext& context) {
  switch (stage) {
    case StepStage::kPhysics:
      step(context.dt);
      break;
    case StepStage::kActuators:
      for (ConstraintActuator* a : actuators_) a->update();
      break;
    case StepStage::kSensors:
      // Ghosts first, at their poses after the attachments stage, so they are current.
      for (RigidBody* g : ghosts_) update_ghost(*g);
      for (ProximitySensor* p : sensors_) p->update();
      break;
    default:
      break;
  }
}

void PhysicsWorld::detach_all() {
  for (Joint* j : joints_) {
    Constraint* c = constraint_of(*j);
    if (c != nullptr && c->world != nullptr) {
      world_->removeConstraint(c->constraint.get());
      c->world = nullptr;
    }
  }
  for (RigidBody* rb : bodies_) {
    Body* b = body_of(*rb);
    if (b != nullptr && b->world != nullptr) {
      world_->removeRigidBody(b->body.get());
      b->world = nullptr;
    }
  }
  // What is left are actuators' holds; then the soft bodies.
  for (int i = world_->getNumConstraints() - 1; i >= 0; --i) {
    btTypedConstraint* t = world_->getConstraint(i);
    if (t->getUserConstraintPtr() != reinterpret_cast<void*>(-1) &&
        t->getUserConstraintPtr() != nullptr) {
      static_cast<Constraint*>(t->getUserConstraintPtr())->world = nullptr;
    }
    world_->removeConstraint(t);
  }
  btSoftBodyArray& softs = world_->getSoftBodyArray();
  while (softs.size() > 0) {
    btSoftBody* sb = softs[softs.size() - 1];
    soft_of(*static_cast<SoftBody*>(sb->getUserPointer()))->world = nullptr;
    world_->removeSoftBody(sb);
  }
  joints_.clear();
  bodies_.clear();
  ghosts_.clear();
  actuators_.clear();
  sensors_.clear();
}

void PhysicsWorld::set_gravity(const Eigen::Vector3d& g) {
  if (!g.allFinite()) throw ArgumentError("gravity must be finite");
  world_->setGravity(to_bullet(g));
  world_->getWorldInfo().m_gravity = to_bullet(g);
}

Eigen::Vector3d PhysicsWorld::gravity() const { return to_eigen(world_->getGravity()); }

void PhysicsWorld::remove(RigidBody& rb) {
  bodies_.erase(std::remove(bodies_.begin(), bodies_.end(), &rb), bodies_.end());
  ghosts_.erase(std::remove(ghosts_.begin(), ghosts_.end(), &rb), ghosts_.end());
  // Ghosts forget a body that goes away.
  for (RigidBody* g : ghosts_) {
    std::vector<Object*>& o = body_of(*g)->overlaps;
    o.erase(std::remove(o.begin(), o.end(), &rb), o.end());
  }
  // Actuators let go of it (or of the body their parent holds) while it still exists.
  const btRigidBody* bullet_body = body_of(rb) ? body_of(rb)->body.get() : nullptr;
  for (int i = world_->getNumConstraints() - 1; i >= 0; --i) {
    btTypedConstraint* t = world_->getConstraint(i);
    void* user = t->getUserConstraintPtr();
    if (user == reinterpret_cast<void*>(-1) || user == nullptr) continue;
    ConstraintActuator* a = static_cast<Constraint*>(user)->actuator;
    if (a != nullptr &&
        (&t->getRigidBodyA() == bullet_body || &t->getRigidBodyB() == bullet_body)) {
      a->deactuate();
    }
  }
}

void PhysicsWorld::remove(Joint& joint) {
  joints_.erase(std::remove(joints_.begin(), joints_.end(), &joint), joints_.end());
  // Its constraint leaves Bullet now, while both bodies still exist.
  if (physics::Constraint* c = constraint_of(joint)) {
    if (c->world != nullptr && c->constraint) c->world->removeConstraint(c->constraint.get());
    c->world = nullptr;
  }
}

void PhysicsWorld::add(RigidBody& rb) {
  const Dynamics& d = rb.dynamics();
  const bool plane = rb.shape().kind == Shape::Kind::kPlane ||
                     (rb.collision().shapes.size() == 1 &&
                      rb.collision().shapes.front().first.kind == Shape::Kind::kPlane);
  if (plane && rb.is_dynamic()) {
    throw ArgumentError("body '" + rb.name() +
                        "': a plane is infinite, so it must be static (mass 0) or "
                        "kinematic");
  }
  auto b = std::make_unique<Body>();
  // The collision mesh of a mesh shape: a separate file, or the visual triangles.
  std::shared_ptr<const MeshData> separate;
  const MeshData* mesh = nullptr;
  const Collision& c = rb.collision();
  if (rb.shape().kind == Shape::Kind::kMesh && c.enabled && c.shapes.empty()) {
    if (!c.mesh.empty()) {
      separate = load_mesh_shared(c.mesh, rb.shape().scale);
      mesh = separate.get();
    } else {
      mesh = rb.visual_mesh().get();
    }
  }
  const bool moving = d.mass > 0 || d.kinematic;
  btCollisionShape* shape = build_shape(*b, rb, mesh, moving);

  // The centre of mass: given, or the collision mesh's vertex mean, or the origin. Bullet's body
  // frame is the centre-of-mass frame, so the shape is placed in it.
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  if (d.inertial_offset) {
    offset = checked_pose(*d.inertial_offset);
  } else if (mesh != nullptr) {
    offset.translation() = mesh_centroid(*mesh);
  }
  if (!offset.matrix().isIdentity(1e-12)) {
    auto compound = std::make_unique<btCompoundShape>();
    compound->addChildShape(to_bullet(offset.inverse()), shape);
    b->shapes.push_back(std::move(compound));
    shape = b->shapes.back().get();
  }
  b->offset = offset;
  btVector3 inertia(0, 0, 0);
  if (d.mass > 0) {
    if (d.inertia) {
      if (!(d.inertia->array() >= 0).all() || !d.inertia->allFinite()) {
        throw ArgumentError("body '" + rb.name() + "': inertia must be >= 0");
      }
      inertia = to_bullet(*d.inertia);
    } else {
      shape->calculateLocalInertia(d.mass, inertia);
    }
  }
  b->inertia = to_eigen(inertia);
  b->motion = std::make_unique<btDefaultMotionState>(to_bullet(rb.pose() * offset));
  btRigidBody::btRigidBodyConstructionInfo info(rb.is_dynamic() ? d.mass : 0.0, b->motion.get(),
                                                shape, rb.is_dynamic() ? inertia : btVector3());
  info.m_friction = d.static_friction;
  info.m_rollingFriction = d.rolling_friction;
  info.m_restitution = d.restitution;
  info.m_linearDamping = d.linear_damping;
  info.m_angularDamping = d.angular_damping;
  b->body = std::make_unique<btRigidBody>(info);
  b->body->setUserPointer(b.get());
  if (d.kinematic) {
    b->body->setCollisionFlags(b->body->getCollisionFlags() |
                               btCollisionObject::CF_KINEMATIC_OBJECT);
    b->body->setActivationState(DISABLE_DEACTIVATION);
  }
  if (!c.enabled) {
    b->body->setCollisionFlags(b->body->getCollisionFlags() |
                               btCollisionObject::CF_NO_CONTACT_RESPONSE);
  }
  if (d.gravity) {
    // Its own gravity, which the world's (now and when it changes) leaves alone.
    b->body->setFlags(b->body->getFlags() | BT_DISABLE_WORLD_GRAVITY);
    b->body->setGravity(to_bullet(*d.gravity));
  }
  b->groups = c.groups;
  b->owner = &rb;
  world_->addRigidBody(b->body.get());
  b->world = world_.get();
  rb.set_physics_state(std::move(b));
  bodies_.push_back(&rb);
}

void PhysicsWorld::refresh(RigidBody& rb) {
  Body& b = *body_of(rb);
  if (b.ghost) return;  // never in the dynamics world
  btRigidBody& body = *b.body;
  world_->removeRigidBody(&body);
  int flags = body.getCollisionFlags() & ~btCollisionObject::CF_KINEMATIC_OBJECT;
  if (rb.dynamics().kinematic) flags |= btCollisionObject::CF_KINEMATIC_OBJECT;
  body.setCollisionFlags(flags);
  if (rb.is_dynamic()) {
    body.setMassProps(rb.dynamics().mass, to_bullet(b.inertia));
    body.setActivationState(ACTIVE_TAG);
    body.forceActivationState(ACTIVE_TAG);
  } else {
    body.setMassProps(0.0, btVector3(0, 0, 0));
    body.setLinearVelocity(btVector3(0, 0, 0));
    body.setAngularVelocity(btVector3(0, 0, 0));
    if (rb.dynamics().kinematic) body.forceActivationState(DISABLE_DEACTIVATION);
  }
  body.updateInertiaTensor();
  world_->addRigidBody(&body);
}

void PhysicsWorld::add(Joint& joint) {
  const JointSpec& s = joint.spec();
  Body& pa = *body_of(*s.parent);
  Body& pb = *body_of(*s.child);
  auto c = std::make_unique<Constraint>();
  const Eigen::Vector3d axis0 = default_axis(s.type);
  c->frame_a = joint_frame(s.parent_pivot, s.parent_axis, s.offset, axis0, pa.offset);
  // The child's offset turns its frame back, so bodies placed as exported sit at position 0.
  c->frame_b = joint_frame(s.child_pivot, s.child_axis, -s.child_offset, axis0, pb.offset);
  btRigidBody& a = *pa.body;
  btRigidBody& b = *pb.body;
  switch (s.type) {
    case JointType::kRevolute: {
      auto hinge = std::make_unique<btHingeConstraint>(a, b, c->frame_a, c->frame_b, false);
      c->constraint = std::move(hinge);
      break;
    }
    case JointType::kPrismatic: {
      auto slider = std::make_unique<btSliderConstraint>(a, b, c->frame_a, c->frame_b, true);
      slider->setLowerLinLimit(1.0);  // free until limited
      slider->setUpperLinLimit(-1.0);
      slider->setLowerAngLimit(0.0);
      slider->setUpperAngLimit(0.0);
      c->constraint = std::move(slider);
      break;
    }
    case JointType::kFixed:
      c->constraint = std::make_unique<btFixedConstraint>(a, b, c->frame_a, c->frame_b);
      break;
    case JointType::kP2P:
      c->constraint = std::make_unique<btPoint2PointConstraint>(a, b, c->frame_a.getOrigin(),
                                                                c->frame_b.getOrigin());
      break;
    case JointType::kConeTwist:
      c->constraint = std::make_unique<btConeTwistConstraint>(a, b, c->frame_a, c->frame_b);
      break;
    case JointType::kLinearSpring:
    case JointType::kTorsionSpring:
    case JointType::kSixDof:
    case JointType::kSixDofSpring: {
      auto six = std::make_unique<btGeneric6DofSpring2Constraint>(a, b, c->frame_a, c->frame_b);
      // Locked everywhere but the degrees of freedom the type has.
      six->setLinearLowerLimit(btVector3(0, 0, 0));
      six->setLinearUpperLimit(btVector3(0, 0, 0));
      six->setAngularLowerLimit(btVector3(0, 0, 0));
      six->setAngularUpperLimit(btVector3(0, 0, 0));
      int dof = -1;
      if (s.type == JointType::kSixDof || s.type == JointType::kSixDofSpring) {
        six->setLinearLowerLimit(btVector3(1, 1, 1));  // free
        six->setLinearUpperLimit(btVector3(-1, -1, -1));
        six->setAngularLowerLimit(btVector3(1, 1, 1));
        six->setAngularUpperLimit(btVector3(-1, -1, -1));
      }
      if (s.type == JointType::kLinearSpring || s.type == JointType::kSixDofSpring) dof = 2;
      if (s.type == JointType::kTorsionSpring) dof = 5;
      if (dof >= 0) {
        six->setLimit(dof, 1.0, -1.0);
        six->enableSpring(dof, true);
        six->setStiffness(dof, s.stiffness);
        six->setDamping(dof, s.damping);
        six->setEquilibriumPoint(dof, s.equilibrium);
      }
      c->constraint = std::move(six);
      break;
    }
  }
  world_->addConstraint(c->constraint.get(), s.ignore_inter_collision);
  c->world = world_.get();
  // A spring keeps its energy: Bullet must not put its bodies to sleep while they swing slowly
  // (a damped spring would freeze short of its equilibrium).
  if (s.type == JointType::kLinearSpring || s.type == JointType::kTorsionSpring ||
      s.type == JointType::kSixDofSpring) {
    for (btRigidBody* body : {&a, &b}) {
      if (!body->isStaticOrKinematicObject()) body->forceActivationState(DISABLE_DEACTIVATION);
    }
  }
  joint.set_physics_state(std::move(c));
  joint.set_limits(s.lower, s.upper);
  a.activate(true);
  b.activate(true);
  joints_.push_back(&joint);
}

double PhysicsWorld::position(const Joint& joint) {
  btTransform a, b;
  joint_frames(joint, a, b);
  const btTransform rel = a.inverseTimes(b);
  const JointType type = joint.type();
  if (rotates(type)) {
    const btMatrix3x3& r = rel.getBasis();
    const double raw = std::atan2(r[1][0], r[0][0]);
    // Continuous through full turns: the nearest to the last step's position.
    const double last = constraint_of(joint)->last_position;
    return last + wrap(raw - last);
  }
  if (type == JointType::kPrismatic) return rel.getOrigin().x();
  if (slides(type)) return rel.getOrigin().z();
  return 0.0;
}

double PhysicsWorld::velocity(const Joint& joint) {
  const JointType type = joint.type();
  if (!rotates(type) && !slides(type)) return 0.0;
  btTransform a, b;
  joint_frames(joint, a, b);
  const btRigidBody& ra = *body_of(joint.parent())->body;
  const btRigidBody& rb = *body_of(joint.child())->body;
  const btVector3 axis = a.getBasis().getColumn(type == JointType::kPrismatic ? 0 : 2);
  if (rotates(type)) return (rb.getAngularVelocity() - ra.getAngularVelocity()).dot(axis);
  // The child's pivot moving relative to the same point carried by the parent.
  const btVector3 p = b.getOrigin();
  const btVector3 vb = rb.getVelocityInLocalPoint(p - rb.getCenterOfMassPosition());
  const btVector3 va = ra.getVelocityInLocalPoint(p - ra.getCenterOfMassPosition());
  return (vb - va).dot(axis);
}

void PhysicsWorld::apply_joint(Joint& joint, double dt) {
  const JointSpec& s = joint.spec();
  const JointType type = joint.type();
  if (!rotates(type) && !slides(type)) {
    joint.effort_ = 0;
    return;
  }
  const double pos = position(joint);
  const double vel = velocity(joint);
  double effort = 0.0;
  bool motor = false;
  double motor_velocity = 0.0;
  switch (joint.command_) {
    case Joint::Command::kPosition: {
      const double error = joint.target_ - pos;
      joint.integral_ += error * dt;
      const JointController& k = s.controller;
      if (k.output == ControlOutput::kEffort) {
        effort = k.p * error + k.i * joint.integral_ - k.d * vel;
      } else {
        // The motor reaches the velocity it is given within the step, so the D term is taken
        // at that velocity: v = P e + I sum(e) - D v, solved for v. (Taken at the last step's
        // velocity instead, D = 1 would make the velocity flip sign every step.)
        motor = true;
        motor_velocity = (k.p * error + k.i * joint.integral_) / (1.0 + k.d);
      }
      break;
    }
    case Joint::Command::kVelocity:
      motor = true;
      motor_velocity = joint.target_;
      break;
    case Joint::Command::kEffort:
      effort = joint.target_;
      break;
    case Joint::Command::kNone:
      break;
  }
  // Springs carry their own damping; other joints get it as an effort.
  if (type == JointType::kRevolute || type == JointType::kPrismatic) effort -= s.damping * vel;
  joint.effort_ = effort;

  btRigidBody& ra = *body_of(joint.parent())->body;
  btRigidBody& rb = *body_of(joint.child())->body;
  btTransform a, b;
  joint_frames(joint, a, b);
  btTypedConstraint* c = constraint_of(joint)->constraint.get();
  // The motor drives the same quantity position() and velocity() measure: the child relative to
  // the parent about (along) the parent's axis.
  if (type == JointType::kRevolute) {
    auto* hinge = static_cast<btHingeConstraint*>(c);
    hinge->enableAngularMotor(motor, -motor_velocity, s.max_motor_impulse);
  } else if (type == JointType::kPrismatic) {
    auto* slider = static_cast<btSliderConstraint*>(c);
    slider->setPoweredLinMotor(motor);
    slider->setTargetLinMotorVelocity(motor_velocity);
    slider->setMaxLinMotorForce(s.max_motor_impulse / dt);
  }
  if (effort != 0.0) {
    if (rotates(type)) {
      const btVector3 torque = a.getBasis().getColumn(2) * effort;
      rb.applyTorque(torque);
      ra.applyTorque(-torque);
    } else {
      const btVector3 force =
          a.getBasis().getColumn(type == JointType::kPrismatic ? 0 : 2) * effort;
      rb.applyForce(force, b.getOrigin() - rb.getCenterOfMassPosition());
      ra.applyForce(-force, b.getOrigin() - ra.getCenterOfMassPosition());
    }
  }
  if (motor || effort != 0.0) {
    ra.activate();
    rb.activate();
  }
}

void PhysicsWorld::step(double dt) {
  bool moving = false;
  for (RigidBody* rb : bodies_) {
    if (!rb->is_dynamic()) continue;
    moving = true;
    btRigidBody& body = *body_of(*rb)->body;
    if (!rb->force().isZero() || !rb->torque().isZero()) {
      body.applyCentralForce(to_bullet(rb->force()));
      body.applyTorque(to_bullet(rb->torque()));
      body.activate();
    }
  }
  if (!moving) moving = soft_bodies_move();
  if (!moving) {
    // Static and kinematic bodies only: nothing for Bullet to simulate, but kinematic bodies
    // take their new poses (for ray tests) without a step.
    for (RigidBody* rb : bodies_) {
      if (!rb->dynamics().kinematic) continue;
      btRigidBody& body = *body_of(*rb)->body;
      btTransform t;
      body_of(*rb)->motion->getWorldTransform(t);
      body.setWorldTransform(t);
      body.setInterpolationWorldTransform(t);
      world_->updateSingleAabb(&body);
    }
    return;
  }
  for (Joint* j : joints_) apply_joint(*j, dt);
  world_->stepSimulation(dt, 1, dt);
  sync_soft_bodies();
  for (RigidBody* rb : bodies_) {
    if (!rb->is_dynamic()) continue;
    const Body& b = *body_of(*rb);
    rb->store_pose(to_eigen(b.body->getWorldTransform()) * b.offset.inverse());
  }
  for (Joint* j : joints_) {
    btTransform a, b;
    joint_frames(*j, a, b);
    j->set_pose(to_eigen(a));
    constraint_of(*j)->last_position = position(*j);
  }
}

}  // namespace physics
}  // namespace ambfplus
