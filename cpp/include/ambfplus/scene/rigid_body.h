#pragma once

#include <array>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "ambfplus/io/mesh.h"
#include "ambfplus/scene/object.h"

namespace ambfplus {

/// Geometry of a body, in the body frame.
struct AMBFPLUS_API Shape {
  enum class Kind { kBox, kSphere, kCylinder, kCapsule, kCone, kPlane, kMesh };
  Kind kind = Kind::kBox;
  /// Box: full extents along x, y, z.
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  /// Sphere, cylinder, capsule, cone: radius.
  double radius = 0.5;
  /// Cylinder, capsule (caps included), cone: height along z, centred on the origin.
  double height = 1.0;
  /// Mesh: file path, and a uniform scale applied to its vertices.
  std::string mesh;
  double scale = 1.0;
  // Planes are z = 0 in the body frame, normal +z, infinite.
};

/// Parses "box", "sphere", "cylinder", "capsule", "cone", "plane", "mesh" (any case).
AMBFPLUS_API Shape::Kind parse_shape_kind(const std::string& name);
AMBFPLUS_API const char* shape_kind_name(Shape::Kind kind);

/// Surface appearance.
struct AMBFPLUS_API Material {
  std::array<float, 4> color{0.8f, 0.8f, 0.8f, 1.0f};  ///< RGBA, 0..1
  float specular = 0.2f;
  float shininess = 32.0f;
};

/// Everything needed to create a rigid body.
struct AMBFPLUS_API RigidBodySpec {
  std::string name;
  Shape shape;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  double mass = 1.0;  ///< kg; 0 makes the body static
  Material material;
};

/// A rigid body: a shape with mass and a material.
class AMBFPLUS_API RigidBody : public Object {
 public:
  ObjectKind kind() const override { return ObjectKind::kRigidBody; }
  const Shape& shape() const { return shape_; }
  double mass() const { return mass_; }
  const Material& material() const { return material_; }
  void set_material(const Material& material) { material_ = material; }
  /// The triangles drawn for this body, in the body frame (shared, immutable).
  const std::shared_ptr<const MeshData>& visual_mesh() const { return visual_mesh_; }

 private:
  friend class Model;
  RigidBody(Model& model, const RigidBodySpec& spec, int id);

  Shape shape_;
  double mass_;
  Material material_;
  std::shared_ptr<const MeshData> visual_mesh_;
};

}  // namespace ambfplus
