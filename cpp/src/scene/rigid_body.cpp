#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include "scene/primitive_meshes.h"

namespace ambfplus {
RigidBody::RigidBody(Model& model, const RigidBodySpec& spec, int id)
    : Object(model, spec.name, id),
      shape_(spec.shape),
      dynamics_(spec.dynamics),
      collision_(spec.collision),
      material_(spec.material) {
  spec.validate();
  if (shape_.kind == Shape::Kind::kNone && collision_.shapes.empty()) collision_.enabled = false;
  set_pose(checked_pose(spec.pose));
  visual_mesh_ = shape_.kind == Shape::Kind::kMesh
                     ? load_mesh_shared(shape_.mesh, shape_.scale)
                     : std::make_shared<const MeshData>(make_primitive_mesh(shape_));
}

RigidBody::~RigidBody() = default;

}  // namespace ambfplus
