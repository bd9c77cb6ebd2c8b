// RigidBodySpec: the names of its kinds, its checks and its keyword options.

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/rigid_body.h"
#include "scene/shared_options.h"
#include "util/strings.h"

namespace ambfplus {
namespace {

void require_positive(double value, const char* what, const std::string& who) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw ArgumentError(who + ": " + what + " must be > 0, got " + std::to_string(value));
  }
}

void require_unit_range(double value, const char* what, const std::string& who) {
  if (!(value >= 0 && value <= 1)) {
    throw ArgumentError(who + ": " + what + " must be in 0..1, got " + std::to_string(value));
  }
}

void require_non_negative(double value, const char* what, const std::string& who) {
  if (!(value >= 0) || !std::isfinite(value)) {
    throw ArgumentError(who + ": " + what + " must be >= 0, got " + std::to_string(value));
  }
}

using Part = std::pair<Shape, Eigen::Matrix4d>;

// A compound collision part from Python: {shape, size, radius, height, axis, pose}.
const OptionTable<Part>& part_options() {
  using O = OptionTable<Part>::Option;
  static const OptionTable<Part> table(
      "a compound part",
      {
          O{"shape", "ShapeKind | str", "box, sphere, cylinder, capsule or cone",
            [](Part& p, const OptionValue& v, const std::string& k) {
              p.first.kind = parse_shape_kind(v.text(k));
            }},
          O{"size", "tuple[float, float, float]", "a box's full extents, m",
            [](Part& p, const OptionValue& v, const std::string& k) {
              p.first.size = v.vector3(k);
            }},
          O{"radius", "float", "m",
            [](Part& p, const OptionValue& v, const std::string& k) {
              p.first.radius = v.number(k);
            }},
          O{"height", "float", "m",
            [](Part& p, const OptionValue& v, const std::string& k) {
              p.first.height = v.number(k);
            }},
          O{"axis", "Axis | str | int", "x, y or z",
            [](Part& p, const OptionValue& v, const std::string& k) {
              p.first.axis = v.is_text() ? static_cast<int>(parse_axis(v.text(k))) : v.integer(k);
            }},
          O{"pose", "numpy.ndarray", "4x4 in the body frame",
            [](Part& p, const OptionValue& v, const std::string& k) { p.second = v.matrix4(k); }},
      });
  return table;
}

// The dimension keywords of add_body a shape needs and takes.
void check_dimensions(RigidBodySpec& s, const std::vector<std::string>& given) {
  auto has = [&](const char* key) {
    for (const std::string& g : given) {
      if (g == key) return true;
    }
    return false;
  };
  if (!has("shape")) s.shape.kind = has("mesh") ? Shape::Kind::kMesh : Shape::Kind::kBox;
  const Shape::Kind kind = s.shape.kind;
  const std::string who = "body '" + s.name + "': ";
  const auto need = [&](bool ok, const char* what) {
    if (!ok) throw ArgumentError(who + "a " + shape_kind_name(kind) + " needs " + what);
  };
  const auto reject = [&](const char* key) {
    if (has(key)) {
      throw ArgumentError(std::string(key) + " does not apply to a " + shape_kind_name(kind) +
                          " body");
    }
  };
  switch (kind) {
    case Shape::Kind::kBox:
      need(has("size"), "size=(x, y, z)");
      reject("radius");
      reject("height");
      break;
    case Shape::Kind::kSphere:
      need(has("radius"), "radius");
      reject("size");
      reject("height");
      break;
    case Shape::Kind::kCylinder:
    case Shape::Kind::kCapsule:
    case Shape::Kind::kCone:
      need(has("radius") && has("height"), "radius and height");
      reject("size");
      break;
    case Shape::Kind::kMesh:
      need(has("mesh"), "mesh='file'");
      [[fallthrough]];
    case Shape::Kind::kPlane:
    case Shape::Kind::kNone:
      reject("size");
      reject("radius");
      reject("height");
      break;
  }
  if (kind != Shape::Kind::kMesh) {
    if (has("mesh")) throw ArgumentError("mesh= needs shape='mesh' (or no shape)");
    if (has("scale") && s.shape.scale != 1.0) {
      throw ArgumentError("scale applies to mesh bodies only");
    }
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
                      "': expected concave (CONCAVE_MESH, TRIMESH), convex_mesh, convex_hull "
                      "(hull) or point_cloud");
}

const char* mesh_collision_name(MeshCollision type) {
  switch (type) {
    case MeshCollision::kConcave:
      return "concave";
    case MeshCollision::kConvexMesh:
      return "convex_mesh";
    case MeshCollision::kConvexHull:
      return "convex_hull";
    case MeshCollision::kPointCloud:
      return "point_cloud";
  }
  return "?";
}

Axis parse_axis(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "x") return Axis::kX;
  if (n == "y") return Axis::kY;
  if (n == "z") return Axis::kZ;
  throw ArgumentError("axis must be 'x', 'y' or 'z', got '" + name + "'");
}

const char* axis_name(Axis axis) {
  switch (axis) {
    case Axis::kX:
      return "x";
    case Axis::kY:
      return "y";
    case Axis::kZ:
      return "z";
  }
  return "?";
}

void Shape::validate(const std::string& who) const {
  if (axis < 0 || axis > 2) throw ArgumentError(who + ": axis must be 0 (x), 1 (y) or 2 (z)");
  switch (kind) {
    case Kind::kBox:
      for (int i = 0; i < 3; ++i) require_positive(size[i], "every box size", who);
      break;
    case Kind::kSphere:
      require_positive(radius, "radius", who);
      break;
    case Kind::kCylinder:
    case Kind::kCone:
      require_positive(radius, "radius", who);
      require_positive(height, "height", who);
      break;
    case Kind::kCapsule:
      require_positive(radius, "radius", who);
      if (!(height >= 2 * radius) || !std::isfinite(height)) {
        throw ArgumentError(who +
                            ": a capsule's height includes its caps, so it must be >= 2 * "
                            "radius");
      }
      break;
    case Kind::kPlane:
    case Kind::kNone:
      break;
    case Kind::kMesh:
      if (mesh.empty()) throw ArgumentError(who + ": a mesh shape needs a mesh file");
      require_positive(scale, "scale", who);
      break;
  }
}

void RigidBodySpec::validate() const {
  const std::string who = "body '" + name + "'";
  const double mass = dynamics.mass;
  if (!(mass >= 0.0) || !std::isfinite(mass)) {
    throw ArgumentError(who + ": mass must be >= 0 kg, got " + std::to_string(mass));
  }
  const Dynamics& d = dynamics;
  require_non_negative(d.static_friction, "friction", who);
  require_non_negative(d.rolling_friction, "rolling friction", who);
  require_unit_range(d.restitution, "restitution", who);
  require_unit_range(d.linear_damping, "linear damping", who);
  require_unit_range(d.angular_damping, "angular damping", who);
  if (d.inertia) {
    if (!d.inertia->allFinite() || !(d.inertia->array() >= 0).all()) {
      throw ArgumentError(who + ": inertia must be finite and >= 0");
    }
  }
  if (d.inertial_offset) checked_pose(*d.inertial_offset, who + " inertial offset");
  if (d.gravity && !d.gravity->allFinite()) throw ArgumentError(who + ": gravity must be finite");
  require_non_negative(collision.margin, "collision margin", who);
  shape.validate(who);
  const bool movable = mass > 0 && !d.kinematic;
  if (shape.kind == Shape::Kind::kPlane && movable) {
    throw ArgumentError(who + ": a plane is infinite, so it must be static (mass 0) or kinematic");
  }
  for (const auto& [part, pose] : collision.shapes) {
    if (part.kind == Shape::Kind::kMesh || part.kind == Shape::Kind::kNone ||
        (part.kind == Shape::Kind::kPlane && collision.shapes.size() > 1)) {
      throw ArgumentError(who + ": compound parts must be primitives (a plane only alone)");
    }
    if (part.kind == Shape::Kind::kPlane && movable) {
      throw ArgumentError(who +
                          ": a plane collision shape is infinite, so its body must be static "
                          "(mass 0) or kinematic");
    }
    part.validate(who);
    checked_pose(pose, who + " collision shape");
  }
  checked_pose(pose, who);
}

const OptionTable<RigidBodySpec>& rigid_body_options() {
  using S = RigidBodySpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "add_body()",
      joined<O>(
      {
          O{"shape", "ShapeKind | str", "box, sphere, cylinder, capsule, cone, plane, mesh, none",
            [](S& s, V v, K k) { s.shape.kind = parse_shape_kind(v.text(k)); }},
          O{"size", "tuple[float, float, float]", "a box's full extents, m",
            [](S& s, V v, K k) { s.shape.size = v.vector3(k); }},
          O{"radius", "float", "m", [](S& s, V v, K k) { s.shape.radius = v.number(k); }},
          O{"height", "float", "m, along the axis (a capsule's includes its caps)",
            [](S& s, V v, K k) { s.shape.height = v.number(k); }},
          O{"axis", "Axis | str | int", "the axis a cylinder, capsule or cone runs along",
            [](S& s, V v, K k) {
              s.shape.axis = v.is_text() ? static_cast<int>(parse_axis(v.text(k))) : v.integer(k);
            }},
          O{"mesh", "str | os.PathLike[str]", "a mesh file",
            [](S& s, V v, K k) { s.shape.mesh = v.text(k); }},
          O{"scale", "float", "of a mesh's vertices",
            [](S& s, V v, K k) { s.shape.scale = v.number(k); }},
          O{"pose", "numpy.ndarray", "4x4 world from body",
            [](S& s, V v, K k) { s.pose = v.matrix4(k); }},
          O{"mass", "float", "kg; 0: static",
            [](S& s, V v, K k) { s.dynamics.mass = v.number(k); }},
          O{"inertia", "tuple[float, float, float]", "principal moments, kg m^2",
            [](S& s, V v, K k) { s.dynamics.inertia = v.vector3(k); }},
          O{"inertial_offset", "numpy.ndarray", "4x4 centre-of-mass frame in the body frame",
            [](S& s, V v, K k) { s.dynamics.inertial_offset = v.matrix4(k); }},
          O{"friction", "float", "static friction",
            [](S& s, V v, K k) { s.dynamics.static_friction = v.number(k); }},
          O{"rolling_friction", "float", "",
            [](S& s, V v, K k) { s.dynamics.rolling_friction = v.number(k); }},
          O{"restitution", "float", "0..1",
            [](S& s, V v, K k) { s.dynamics.restitution = v.number(k); }},
          O{"linear_damping", "float", "0..1",
            [](S& s, V v, K k) { s.dynamics.linear_damping = v.number(k); }},
          O{"angular_damping", "float", "0..1",
            [](S& s, V v, K k) { s.dynamics.angular_damping = v.number(k); }},
          O{"kinematic", "bool", "moved only by setting its pose",
            [](S& s, V v, K k) { s.dynamics.kinematic = v.boolean(k); }},
          O{"gravity", "tuple[float, float, float]", "m/s^2: its own, instead of the world's",
            [](S& s, V v, K k) { s.dynamics.gravity = v.vector3(k); }},
          O{"collision", "bool", "False: collides with nothing",
            [](S& s, V v, K k) { s.collision.enabled = v.boolean(k); }},
          O{"collision_mesh", "str | os.PathLike[str]", "a separate collision mesh file",
            [](S& s, V v, K k) { s.collision.mesh = v.text(k); }},
          O{"collision_type", "MeshCollision | str",
            "concave, convex_mesh, convex_hull or point_cloud",
            [](S& s, V v, K k) { s.collision.mesh_type = parse_mesh_collision(v.text(k)); }},
          O{"collision_shapes", "list[dict[str, Any]]",
            "[{shape, size/radius/height/axis, pose}]: a compound of primitives",
            [](S& s, V v, K k) {
              for (const OptionValue& item : v.list(k)) {
                Part part{Shape{}, Eigen::Matrix4d::Identity()};
                part_options().apply(part, item.map(k));
                s.collision.shapes.push_back(part);
              }
            }},
          O{"margin", "float", "collision margin, m",
            [](S& s, V v, K k) { s.collision.margin = v.number(k); }},
          O{"groups", "list[int]", "collision groups, 0..31",
            [](S& s, V v, K k) {
              for (int g : v.integers(k)) {
                if (g < 0 || g > 31) throw ArgumentError("collision groups are 0..31");
                s.collision.groups |= 1u << g;
              }
            }},
      },
                material_options(&S::material)),
      check_dimensions);
  return table;
}

}  // namespace ambfplus
