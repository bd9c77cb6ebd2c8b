#pragma once

#include "ambfplus/io/mesh.h"
#include "physics/physics_world.h"

namespace ambfplus {

class RigidBody;

namespace physics {

/// The mean of a mesh's vertices (AMBF's default centre of mass for a collision mesh).
Eigen::Vector3d mesh_centroid(const MeshData& mesh);

/// The body's collision shape in its body frame, owned by `out` (with any mesh data it points
/// into). `mesh` is the collision mesh for mesh shapes; concave meshes become a BVH for static
/// bodies and GImpact for moving ones.
btCollisionShape* build_shape(Body& out, const RigidBody& body, const MeshData* mesh, bool dynamic);

}  // namespace physics
}  // namespace ambfplus
