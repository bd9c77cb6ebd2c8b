#pragma once

// Bullet behind the engine's own interfaces: no public header names a Bullet type.

#include <memory>
#include <optional>
#include <vector>

#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <Eigen/Geometry>

#include "ambfplus/physics/physics.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/soft_body.h"

namespace ambfplus {

class ConstraintActuator;
class Joint;
class ProximitySensor;
class RigidBody;
class SoftBody;

namespace physics {

Eigen::Isometry3d to_eigen(const btTransform& t);
btTransform to_bullet(const Eigen::Isometry3d& t);
inline btVector3 to_bullet(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Eigen::Vector3d to_eigen(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

/// A body's Bullet side: its shapes (and the mesh data they point into) and the rigid body.
struct Body : ObjectState {
  ~Body() override;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;  // the last one is the body's
  std::vector<std::unique_ptr<btStridingMeshInterface>> meshes;
  std::vector<std::vector<btScalar>> vertices;
  std::vector<std::vector<int>> indices;
  std::unique_ptr<btDefaultMotionState> motion;
  std::unique_ptr<btRigidBody> body;
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();  // centre of mass in the body frame
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();
  std::uint32_t groups = 0;
  btDynamicsWorld* world = nullptr;  // while in one
  RigidBody* owner = nullptr;        // the scene body (ray hits name it)
  /// A ghost's collision object (its body then stays out of Bullet's world) and the rigid and
  /// soft bodies overlapping it after the last step.
  std::unique_ptr<btCollisionObject> ghost;
  std::vector<Object*> overlaps;
  bool warned_concave = false;  // that soft bodies cannot be tested against its mesh
};

/// A soft body's Bullet side (its user pointer is the scene SoftBody).
struct Soft : ObjectState {
  ~Soft() override;
  std::unique_ptr<btSoftBody> body;
  btSoftRigidDynamicsWorld* world = nullptr;  // while in one
  double node_mass = 0.0;                     // of each free node, kg
};

/// The nearest thing a ray segment met.
struct RayHit {
  bool hit = false;
  double fraction = 1.0;  // along the segment
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  RigidBody* body = nullptr;
  SoftBody* soft_body = nullptr;
  int soft_body_node = -1;
};

/// A joint's (or an actuator's hold's) Bullet constraint and its frames (in each body's
/// centre-of-mass frame).
struct Constraint : ObjectState {
  ~Constraint() override;
  std::unique_ptr<btTypedConstraint> constraint;
  btTransform frame_a, frame_b;
  btDynamicsWorld* world = nullptr;
  double last_position = 0.0;
  ConstraintActuator* actuator = nullptr;  // an actuator's hold (its user pointer is this)
  std::optional<SixDofAxes> six_dof;       // a six dof joint's per-axis settings, once given
};

/// The Bullet side of objects, as their physics state (Object::physics_state); nullptr for
/// an object physics does not hold (yet, or any more).
inline Body* body_of(const RigidBody& body) { return static_cast<Body*>(body.physics_state()); }
inline Soft* soft_of(const SoftBody& body) { return static_cast<Soft*>(body.physics_state()); }
inline Constraint* constraint_of(const Object& joint_or_actuator) {
  return static_cast<Constraint*>(joint_or_actuator.physics_state());
}

/// One Bullet world per scene world: bodies, joints, their controllers, actuators and sensors,
/// a fixed step.
class PhysicsWorld : public Physics {
 public:
  PhysicsWorld();
  ~PhysicsWorld() override;
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  // System
  const char* name() const override { return "physics"; }
  unsigned stages() const override {
    return stage_bit(StepStage::kPhysics) | stage_bit(StepStage::kActuators) |
           stage_bit(StepStage::kSensors);
  }
  void object_added(Object& object) override;
  void object_removed(Object& object) override;
  void run(StepStage stage, const StepContext& context) override;
  /// Takes every body and constraint out of Bullet (before the scene objects go away).
  void detach_all() override;

  /// Builds the body's Bullet side and adds it. Throws ArgumentError for geometry Bullet
  /// cannot simulate (a dynamic plane).
  void add(RigidBody& body);
  void add(Joint& joint);
  /// Builds the soft body's nodes, links and faces in Bullet and adds it.
  void add(SoftBody& body);
  /// The nearest body along the segment from -> to, skipping `ignore` and bodies without
  /// collision.
  RayHit ray_test(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                  const RigidBody* ignore) const;
  /// Re-adds a body whose kind (static, kinematic, dynamic) changed.
  void refresh(RigidBody& body);
  /// Forgets a body or joint about to be deleted (its own destructor takes it out of Bullet).
  void remove(RigidBody& body);
  void remove(Joint& joint);
  /// Turns an added body into a ghost: out of the dynamics world, tested for overlaps instead.
  void make_ghost(RigidBody& body);
  /// Moves a ghost's collision object to its body's pose and finds what overlaps it.
  void update_ghost(RigidBody& body);

  /// Controllers and commands, one Bullet step of dt, then poses back into the scene.
  void step(double dt);

  void set_gravity(const Eigen::Vector3d& g) override;
  Eigen::Vector3d gravity() const override;

  /// Joint state from Bullet.
  static double position(const Joint& joint);
  static double velocity(const Joint& joint);

  btSoftRigidDynamicsWorld& bullet() { return *world_; }

 private:
  void apply_joint(Joint& joint, double dt);
  /// Whether a soft body has a node physics moves.
  bool soft_bodies_move() const;
  /// Soft-body nodes back into the scene, and the soft bodies' distance cache trimmed.
  void sync_soft_bodies();

  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btOverlapFilterCallback> filter_;
  std::unique_ptr<btSoftRigidDynamicsWorld> world_;
  std::vector<RigidBody*> bodies_;
  std::vector<Joint*> joints_;
  std::vector<ConstraintActuator*> actuators_;
  std::vector<ProximitySensor*> sensors_;
  std::vector<RigidBody*> ghosts_;
};

/// The physics of an object's world.
PhysicsWorld& physics_of(const Object& object);

}  // namespace physics
}  // namespace ambfplus
