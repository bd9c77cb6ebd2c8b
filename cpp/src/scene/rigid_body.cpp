#include "ambfplus/scene/rigid_body.h"

#include <cmath>
#include <stdexcept>

#include "scene/primitive_meshes.h"
#include "util/strings.h"

namespace ambfplus {
namespace {

void require_positive(double value, const char* what, const std::string& body) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument("body '" + body + "': " + what + " must be > 0, got " +
                                std::to_string(value));
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
  throw std::invalid_argument("unknown shape '" + name +
                              "': expected box, sphere, cylinder, capsule, cone, plane or mesh");
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
  }
  return "?";
}

RigidBody::RigidBody(Model& model, const RigidBodySpec& spec, int id)
    : Object(model, spec.name, id), shape_(spec.shape), mass_(spec.mass), material_(spec.material) {
  const std::string& name = spec.name;
  if (!(mass_ >= 0.0) || !std::isfinite(mass_)) {
    throw std::invalid_argument("body '" + name + "': mass must be >= 0 kg, got " +
                                std::to_string(mass_));
  }
  switch (shape_.kind) {
    case Shape::Kind::kBox:
      for (int i = 0; i < 3; ++i) require_positive(shape_.size[i], "every box size", name);
      break;
    case Shape::Kind::kSphere:
      require_positive(shape_.radius, "radius", name);
      break;
    case Shape::Kind::kCylinder:
    case Shape::Kind::kCone:
      require_positive(shape_.radius, "radius", name);
      require_positive(shape_.height, "height", name);
      break;
    case Shape::Kind::kCapsule:
      require_positive(shape_.radius, "radius", name);
      if (!(shape_.height >= 2 * shape_.radius)) {
        throw std::invalid_argument("body '" + name +
                                    "': a capsule's height includes its caps, so it must be >= "
                                    "2 * radius");
      }
      break;
    case Shape::Kind::kPlane:
      break;
    case Shape::Kind::kMesh:
      if (shape_.mesh.empty()) {
        throw std::invalid_argument("body '" + name + "': a mesh shape needs a mesh file");
      }
      require_positive(shape_.scale, "scale", name);
      break;
  }
  set_pose(checked_pose(spec.pose));
  visual_mesh_ = std::make_shared<const MeshData>(shape_.kind == Shape::Kind::kMesh
                                                      ? load_mesh(shape_.mesh, shape_.scale)
                                                      : make_primitive_mesh(shape_));
}

}  // namespace ambfplus
