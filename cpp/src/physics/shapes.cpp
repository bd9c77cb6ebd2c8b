#include "physics/shapes.h"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <stdexcept>

#include "ambfplus/errors.h"
#include "ambfplus/scene/rigid_body.h"

namespace ambfplus {
namespace physics {
namespace {

// A primitive in its own frame (Bullet's capsules count their height without the caps).
std::unique_ptr<btCollisionShape> primitive(const Shape& s, const std::string& body) {
  const double h = s.height / 2;
  switch (s.kind) {
    case Shape::Kind::kBox:
      return std::make_unique<btBoxShape>(to_bullet(Eigen::Vector3d(s.size / 2)));
    case Shape::Kind::kSphere:
      return std::make_unique<btSphereShape>(s.radius);
    case Shape::Kind::kCylinder:
      if (s.axis == 0) return std::make_unique<btCylinderShapeX>(btVector3(h, s.radius, s.radius));
      if (s.axis == 1) return std::make_unique<btCylinderShape>(btVector3(s.radius, h, s.radius));
      return std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, h));
    case Shape::Kind::kCapsule:
      if (s.axis == 0) return std::make_unique<btCapsuleShapeX>(s.radius, s.height - 2 * s.radius);
      if (s.axis == 1) return std::make_unique<btCapsuleShape>(s.radius, s.height - 2 * s.radius);
      return std::make_unique<btCapsuleShapeZ>(s.radius, s.height - 2 * s.radius);
    case Shape::Kind::kCone:
      if (s.axis == 0) return std::make_unique<btConeShapeX>(s.radius, s.height);
      if (s.axis == 1) return std::make_unique<btConeShape>(s.radius, s.height);
      return std::make_unique<btConeShapeZ>(s.radius, s.height);
    case Shape::Kind::kPlane:
      return std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
    case Shape::Kind::kNone:
      return std::make_unique<btEmptyShape>();
    case Shape::Kind::kMesh:
      break;
  }
  throw ArgumentError("body '" + body + "': a mesh cannot be a compound's part");
}

}  // namespace

Eigen::Vector3d mesh_centroid(const MeshData& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const std::size_t n = mesh.vertex_count();
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = &mesh.positions[i * mesh.position_size];
    sum += Eigen::Vector3d(p[0], p[1], p[2]);
  }
  return n > 0 ? Eigen::Vector3d(sum / static_cast<double>(n)) : sum;
}

btCollisionShape* build_shape(Body& out, const RigidBody& rb, const MeshData* mesh, bool dynamic) {
  const Collision& c = rb.collision();
  const Shape& s = rb.shape();
  auto keep = [&](std::unique_ptr<btCollisionShape> shape) {
    shape->setMargin(c.margin);
    out.shapes.push_back(std::move(shape));
    return out.shapes.back().get();
  };
  if (!c.enabled) return keep(std::make_unique<btEmptyShape>());
  if (c.shapes.size() == 1 && c.shapes.front().first.kind == Shape::Kind::kPlane) {
    // A plane is infinite, so it cannot sit in a compound: its normal and offset take the pose.
    const Eigen::Matrix4d& pose = c.shapes.front().second;
    const Eigen::Vector3d normal = pose.topLeftCorner<3, 3>().col(2);
    const double constant = normal.dot(pose.topRightCorner<3, 1>());
    return keep(std::make_unique<btStaticPlaneShape>(to_bullet(normal), constant));
  }
  if (!c.shapes.empty()) {
    auto compound = std::make_unique<btCompoundShape>();
    for (const auto& [part, pose] : c.shapes) {
      btCollisionShape* child = keep(primitive(part, rb.name()));
      Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
      t.matrix() = pose;
      compound->addChildShape(to_bullet(t), child);
    }
    return keep(std::move(compound));
  }
  if (s.kind != Shape::Kind::kMesh) return keep(primitive(s, rb.name()));

  // A mesh: its vertices and triangles, in the body frame.
  std::vector<btScalar> vertices;
  const std::size_t n = mesh->vertex_count();
  vertices.reserve(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) vertices.push_back(mesh->positions[i * mesh->position_size + a]);
  }
  if (n == 0) return keep(std::make_unique<btEmptyShape>());
  switch (c.mesh_type) {
    case MeshCollision::kConvexHull: {
      btConvexHullShape full(vertices.data(), static_cast<int>(n), 3 * sizeof(btScalar));
      full.setMargin(c.margin);
      btShapeHull hull(&full);
      hull.buildHull(c.margin);
      auto shape = std::make_unique<btConvexHullShape>(
          reinterpret_cast<const btScalar*>(hull.getVertexPointer()), hull.numVertices(),
          sizeof(btVector3));
      return keep(std::move(shape));
    }
    case MeshCollision::kConvexMesh:
      return keep(std::make_unique<btConvexHullShape>(vertices.data(), static_cast<int>(n),
                                                      3 * sizeof(btScalar)));
    case MeshCollision::kPointCloud: {
      auto compound = std::make_unique<btCompoundShape>();
      for (std::size_t i = 0; i < n; ++i) {
        btCollisionShape* sphere = keep(std::make_unique<btSphereShape>(c.margin));
        btTransform t;
        t.setIdentity();
        t.setOrigin(btVector3(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]));
        compound->addChildShape(t, sphere);
      }
      return keep(std::move(compound));
    }
    case MeshCollision::kConcave:
      break;
  }
  // The triangles themselves: a BVH for static bodies, GImpact for moving ones.
  out.vertices.push_back(std::move(vertices));
  out.indices.emplace_back(mesh->indices.begin(), mesh->indices.end());
  auto array = std::make_unique<btTriangleIndexVertexArray>(
      static_cast<int>(mesh->triangle_count()), out.indices.back().data(), 3 * sizeof(int),
      static_cast<int>(n), out.vertices.back().data(), 3 * sizeof(btScalar));
  btTriangleIndexVertexArray* raw = array.get();
  out.meshes.push_back(std::move(array));
  if (!dynamic) return keep(std::make_unique<btBvhTriangleMeshShape>(raw, true));
  auto gimpact = std::make_unique<btGImpactMeshShape>(raw);
  gimpact->setMargin(c.margin);
  gimpact->updateBound();
  return keep(std::move(gimpact));
}

}  // namespace physics
}  // namespace ambfplus
