#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/io/mesh.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/shader_spec.h"

namespace ambfplus {

/// Geometry of a body, in the body frame.
struct AMBFPLUS_API Shape {
  /// kNone: no geometry, an invisible anchor that collides with nothing (AMBF's `mesh: ''`).
  enum class Kind { kBox, kSphere, kCylinder, kCapsule, kCone, kPlane, kMesh, kNone };
  Kind kind = Kind::kBox;
  /// Box: full extents along x, y, z.
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  /// Sphere, cylinder, capsule, cone: radius.
  double radius = 0.5;
  /// Cylinder, capsule (caps included), cone: height along z, centred on the origin.
  double height = 1.0;
  /// Cylinder, capsule, cone: the body axis they run along (0 = x, 1 = y, 2 = z).
  int axis = 2;
  /// Mesh: file path, and a uniform scale applied to its vertices. Other shapes only record the
  /// scale their dimensions were given with (AMBF's `scale`, which also scales joint pivots).
  std::string mesh;
  double scale = 1.0;
  // Planes are z = 0 in the body frame, normal +z, infinite.

  /// Throws ArgumentError (naming `who`, e.g. "body 'b'") unless the dimensions fit the kind.
  void validate(const std::string& who) const;
};

/// A body axis: what Shape::axis holds (0, 1, 2).
enum class Axis { kX = 0, kY = 1, kZ = 2 };
/// Parses "x", "y", "z" (any case).
AMBFPLUS_API Axis parse_axis(const std::string& name);
AMBFPLUS_API const char* axis_name(Axis axis);

/// How a body's collision geometry is made from a mesh.
enum class MeshCollision {
  kConcave,     ///< the triangles themselves (AMBF's default)
  kConvexMesh,  ///< the triangles' vertices as a convex shape
  kConvexHull,  ///< the convex hull of the vertices, simplified
  kPointCloud,  ///< the vertices as small spheres
};
/// Parses AMBF's collision mesh types (CONCAVE_MESH, TRIMESH, CONVEX_MESH, CONVEX_HULL, hull,
/// POINT_CLOUD, in any case).
AMBFPLUS_API MeshCollision parse_mesh_collision(const std::string& name);
/// "concave", "convex_mesh", "convex_hull" or "point_cloud".
AMBFPLUS_API const char* mesh_collision_name(MeshCollision type);

/// A body's collision geometry, in the body frame.
struct AMBFPLUS_API Collision {
  bool enabled = true;  ///< false: the body collides with nothing (an anchor)
  /// Primitives making a compound shape, each placed in the body frame. Empty: the body's own
  /// shape (or, for a mesh, `mesh` or the visual mesh). A plane may be the only part (of a body
  /// that does not move): its z = 0 plane, placed by the part's pose.
  std::vector<std::pair<Shape, Eigen::Matrix4d>> shapes;
  std::string mesh;  ///< a separate collision mesh file (same scale as the shape), or ""
  MeshCollision mesh_type = MeshCollision::kConcave;
  double margin = 0.001;  ///< m
  /// Collision groups, bits 0..31: two bodies collide when they share a group or when either is
  /// in none.
  std::uint32_t groups = 0;
};

/// Mass properties and contact parameters (AMBF's defaults).
struct AMBFPLUS_API Dynamics {
  double mass = 1.0;  ///< kg; 0 makes the body static
  /// Principal moments about the centre of mass, kg m^2; absent: from the collision shape.
  std::optional<Eigen::Vector3d> inertia;
  /// The centre-of-mass frame in the body frame; absent: the origin, or for a collision mesh the
  /// mean of its vertices.
  std::optional<Eigen::Matrix4d> inertial_offset;
  double static_friction = 0.5;
  double rolling_friction = 0.01;
  double restitution = 0.1;
  double linear_damping = 0.04;
  double angular_damping = 0.1;
  /// Moved only by set_pose (and drills it is attached to), pushing dynamic bodies aside.
  bool kinematic = false;
  /// This body's own gravity, m/s^2 (AMBF's body or model `gravity`); absent: the world's.
  std::optional<Eigen::Vector3d> gravity;
};

/// Parses "box", "sphere", "cylinder", "capsule", "cone", "plane", "mesh", "none" (any case).
AMBFPLUS_API Shape::Kind parse_shape_kind(const std::string& name);
AMBFPLUS_API const char* shape_kind_name(Shape::Kind kind);

/// Surface appearance.
struct AMBFPLUS_API Material {
  std::array<float, 4> color{0.8f, 0.8f, 0.8f, 1.0f};  ///< RGBA, 0..1 (diffuse)
  float specular = 0.2f;
  float shininess = 32.0f;
  /// Ambient reflectance (AMBF's material ambient, which its segmentation shaders draw); unset:
  /// half the colour, as AMBF's `color rgba` gives.
  std::optional<std::array<float, 3>> ambient;
  /// The shader drawing this surface; unset: the model's, else the world's, else the engine's.
  std::optional<ShaderSpec> shader;
  /// Drawn by cameras (AMBF's `visible`); hidden surfaces still collide.
  bool visible = true;

  /// ambient, or half the colour when unset.
  std::array<float, 3> ambient_color() const {
    return ambient ? *ambient
                   : std::array<float, 3>{0.5f * color[0], 0.5f * color[1], 0.5f * color[2]};
  }
};

/// Everything needed to create a rigid body.
struct AMBFPLUS_API RigidBodySpec {
  std::string name;
  Shape shape;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  Dynamics dynamics;
  Collision collision;
  Material material;

  /// Throws ArgumentError naming the body and the value unless every value can be used (finite,
  /// in range, consistent); the constructor calls it, the ADF loader too before creating anything.
  void validate() const;
};

/// add_body's keyword options: shape, size, radius, height, axis, mesh, scale, pose, mass, color,
/// specular, shininess, visible, inertia, inertial_offset, friction, rolling_friction, restitution,
/// linear_damping, angular_damping, kinematic, collision, collision_mesh, collision_type,
/// collision_shapes, margin, groups; a shape's dimensions must fit it (a box needs size, a
/// sphere takes no height ...).
AMBFPLUS_API const OptionTable<RigidBodySpec>& rigid_body_options();

namespace physics {
class PhysicsWorld;
}  // namespace physics

/// A rigid body: a shape with mass and a material, simulated by the world's physics (gravity,
/// contacts, joints) when it has mass and is not kinematic.
class AMBFPLUS_API RigidBody : public Object {
 public:
  ~RigidBody() override;
  ObjectKind kind() const override { return ObjectKind::kRigidBody; }
  const Shape& shape() const { return shape_; }
  double mass() const { return dynamics_.mass; }
  const Dynamics& dynamics() const { return dynamics_; }
  const Collision& collision() const { return collision_; }
  const Material& material() const { return material_; }
  void set_material(const Material& material) { material_ = material; }
  /// The triangles drawn for this body, in the body frame (shared, immutable).
  const std::shared_ptr<const MeshData>& visual_mesh() const { return visual_mesh_; }

  /// Moves the body there at once (velocities are kept).
  void set_pose(const Eigen::Isometry3d& pose) override;
  /// Moves only by physics: mass > 0 and not kinematic.
  bool is_dynamic() const { return dynamics_.mass > 0 && !dynamics_.kinematic; }
  void set_kinematic(bool kinematic);

  /// Velocity of the body frame's origin and angular velocity, world frame.
  Eigen::Vector3d linear_velocity() const;
  Eigen::Vector3d angular_velocity() const;
  void set_linear_velocity(const Eigen::Vector3d& v);
  void set_angular_velocity(const Eigen::Vector3d& w);
  /// A force (N, world frame) applied at the centre of mass, and a torque (N m), every step until
  /// changed (as AMBF's commands are).
  void set_force(const Eigen::Vector3d& f);
  void set_torque(const Eigen::Vector3d& t);
  const Eigen::Vector3d& force() const { return force_; }
  const Eigen::Vector3d& torque() const { return torque_; }
  /// Principal moments of inertia (kg m^2) and the centre-of-mass frame in the body frame.
  Eigen::Vector3d inertia() const;
  Eigen::Isometry3d inertial_offset() const;
  /// Where the centre of mass is, world frame.
  Eigen::Vector3d center_of_mass() const { return pose() * inertial_offset().translation(); }

  void set_friction(double static_friction, double rolling_friction);
  void set_restitution(double restitution);
  void set_damping(double linear, double angular);
  /// This body and other pass through each other (AMBF's model-wide `ignore inter-collision`).
  void ignore_collisions_with(RigidBody& other);

 private:
  friend class Model;
  friend class physics::PhysicsWorld;
  RigidBody(Model& model, const RigidBodySpec& spec, int id);
  void store_pose(const Eigen::Isometry3d& pose) { Object::set_pose(pose); }

  Shape shape_;
  Dynamics dynamics_;
  Collision collision_;
  Material material_;
  std::shared_ptr<const MeshData> visual_mesh_;
  Eigen::Vector3d force_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_ = Eigen::Vector3d::Zero();
};

}  // namespace ambfplus
