#pragma once

#include "ambfplus/io/mesh.h"
#include "ambfplus/scene/rigid_body.h"

namespace ambfplus {

/// Triangles for a primitive shape in its body frame (outward normals, counter-clockwise seen
/// from outside). Planes come back as a fan to points at infinity (position_size 4).
MeshData make_primitive_mesh(const Shape& shape);

}  // namespace ambfplus
