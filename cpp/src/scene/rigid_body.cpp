#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "scene/primitive_meshes.h"
#include "util/strings.h"

namespace ambfplus {
namespace {

void require_positive(double value, const char* what, const std::string& body) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw ArgumentError("body '" + body + "': " + what + " must be > 0, got " +
                        std::to_string(value));
  }
}

// Throws unless the shape's dimensions make sense.
void check_shape(const Shape& shape, const std::string& name) {
  switch (shape.kind) {
    case Shape::Kind::kBox:
      for (int i = 0; i < 3; ++i) require_positive(shape.size[i], "every box size", name);
      break;
    case Shape::Kind::kSphere:
      require_positive(shape.radius, "radius", name);
      break;
    case Shape::Kind::kCylinder:
    case Shape::Kind::kCone:
      require_positive(shape.radius, "radius", name);
      require_positive(shape.height, "height", name);
      break;
    case Shape::Kind::kCapsule:
      require_positive(shape.radius, "radius", name);
      if (!(shape.height >= 2 * shape.radius)) {
        throw ArgumentError("body '" + name +
                            "': a capsule's height includes its caps, so it must be >= "
                            "2 * radius");
      }
      break;
    case Shape::Kind::kPlane:
    case Shape::Kind::kNone:
      break;
    case Shape::Kind::kMesh:
      if (shape.mesh.empty()) {
        throw ArgumentError("body '" + name + "': a mesh shape needs a mesh file");
      }
      require_positive(shape.scale, "scale", name);
      break;
  }
}

}  // namespace

Shape::Kind parse_shape_kind(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "box") return Shape::Kind::kBox;
  if (n == "sphere") return Shape::Kind::kSphere;
  if (n == "cylinder") return Shape::Kind::kCylinder;
  if (n == "capsule") return Shape::Kind::kCapsule;
  if (n == "cone") return Shape::Kind::kCone;
  if (n == "plane") return Shape::Kind::kPlane;
  if (n == "mesh") return Shape::Kind::kMesh;
  if (n == "none") return Shape::Kind::kNone;
  throw ArgumentError("unknown shape '" + name +
                      "': expected box, sphere, cylinder, capsule, cone, plane, mesh or none");
}

const char* shape_kind_name(Shape::Kind kind) {
  switch (kind) {
    case Shape::Kind::kBox:
      return "box";
    case Shape::Kind::kSphere:
      return "sphere";
    case Shape::Kind::kCylinder:
      return "cylinder";
    case Shape::Kind::kCapsule:
      return "capsule";
    case Shape::Kind::kCone:
      return "cone";
    case Shape::Kind::kPlane:
      return "plane";
    case Shape::Kind::kMesh:
      return "mesh";
    case Shape::Kind::kNone:
      return "none";
  }
  return "?";
}

MeshCollision parse_mesh_collision(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "concave_mesh" || n == "trimesh" || n == "concave") return MeshCollision::kConcave;
  if (n == "convex_mesh") return MeshCollision::kConvexMesh;
  if (n == "convex_hull" || n == "hull") return MeshCollision::kConvexHull;
  if (n == "point_cloud") return MeshCollision::kPointCloud;
  throw ArgumentError("unknown collision mesh type '" + name +
                      "': expected CONCAVE_MESH, TRIMESH, CONVEX_MESH, CONVEX_HULL, hull "
                      "or POINT_CLOUD");
}

RigidBody::RigidBody(Model& model, const RigidBodySpec& spec, int id)
    : Object(model, spec.name, id),
      shape_(spec.shape),
      dynamics_(spec.dynamics),
      collision_(spec.collision),
      material_(spec.material) {
  const std::string& name = spec.name;
  const double mass = dynamics_.mass;
  if (!(mass >= 0.0) || !std::isfinite(mass)) {
    throw ArgumentError("body '" + name + "': mass must be >= 0 kg, got " + std::to_string(mass));
  }
  const Dynamics& d = dynamics_;
  for (double v : {d.static_friction, d.rolling_friction}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      throw ArgumentError("body '" + name + "': friction must be >= 0");
    }
  }
  if (!(d.restitution >= 0 && d.restitution <= 1)) {
    throw ArgumentError("body '" + name + "': restitution must be in 0..1");
  }
  if (!(d.linear_damping >= 0 && d.linear_damping <= 1) ||
      !(d.angular_damping >= 0 && d.angular_damping <= 1)) {
    throw ArgumentError("body '" + name + "': damping must be in 0..1");
  }
  if (shape_.kind == Shape::Kind::kNone && collision_.shapes.empty()) collision_.enabled = false;
  if (!(collision_.margin >= 0) || !std::isfinite(collision_.margin)) {
    throw ArgumentError("body '" + name + "': collision margin must be >= 0");
  }
  if (shape_.axis < 0 || shape_.axis > 2) {
    throw ArgumentError("body '" + name + "': axis must be 0 (x), 1 (y) or 2 (z)");
  }
  check_shape(shape_, name);
  for (const auto& [part, pose] : collision_.shapes) {
    if (part.kind == Shape::Kind::kMesh || part.kind == Shape::Kind::kNone ||
        (part.kind == Shape::Kind::kPlane && collision_.shapes.size() > 1)) {
      throw ArgumentError("body '" + name +
                          "': compound parts must be primitives (a plane only alone)");
    }
    check_shape(part, name);
    checked_pose(pose);
  }
  set_pose(checked_pose(spec.pose));
  visual_mesh_ = shape_.kind == Shape::Kind::kMesh
                     ? load_mesh_shared(shape_.mesh, shape_.scale)
                     : std::make_shared<const MeshData>(make_primitive_mesh(shape_));
}

RigidBody::~RigidBody() = default;

}  // namespace ambfplus
