#pragma once

// Bullet behind the engine's own interfaces: no public header names a Bullet type.

#include <memory>
#include <vector>

#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <Eigen/Geometry>

namespace ambfplus {

class Joint;
class RigidBody;

namespace physics {

Eigen::Isometry3d to_eigen(const btTransform& t);
btTransform to_bullet(const Eigen::Isometry3d& t);
inline btVector3 to_bullet(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Eigen::Vector3d to_eigen(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

/// A body's Bullet side: its shapes (and the mesh data they point into) and the rigid body.
struct Body {
  ~Body();
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
};

/// A joint's Bullet constraint and its frames (in each body's centre-of-mass frame).
struct Constraint {
  ~Constraint();
  std::unique_ptr<btTypedConstraint> constraint;
  btTransform frame_a, frame_b;
  btDynamicsWorld* world = nullptr;
  double last_position = 0.0;
};

/// One Bullet world per scene world: bodies, joints, their controllers, a fixed step.
class PhysicsWorld {
 public:
  PhysicsWorld();
  ~PhysicsWorld();
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  /// Builds the body's Bullet side and adds it. Throws std::invalid_argument for geometry Bullet
  /// cannot simulate (a dynamic plane).
  void add(RigidBody& body);
  void add(Joint& joint);
  /// Re-adds a body whose kind (static, kinematic, dynamic) changed.
  void refresh(RigidBody& body);

  /// Controllers and commands, one Bullet step of dt, then poses back into the scene.
  void step(double dt);

  void set_gravity(const Eigen::Vector3d& g);
  Eigen::Vector3d gravity() const;
  /// Takes every body and constraint out of Bullet (before the scene objects go away).
  void detach_all();

  /// Joint state from Bullet.
  static double position(const Joint& joint);
  static double velocity(const Joint& joint);

  btSoftRigidDynamicsWorld& bullet() { return *world_; }

 private:
  void apply_joint(Joint& joint, double dt);

  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btOverlapFilterCallback> filter_;
  std::unique_ptr<btSoftRigidDynamicsWorld> world_;
  std::vector<RigidBody*> bodies_;
  std::vector<Joint*> joints_;
};

}  // namespace physics
}  // namespace ambfplus
