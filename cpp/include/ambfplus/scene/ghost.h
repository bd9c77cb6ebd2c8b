#pragma once

// Ghost objects (AMBF's `ghost objects`): bodies that touch nothing but report what overlaps
// them.

#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/rigid_body.h"

namespace ambfplus {

class Model;

/// Adds a ghost to model: a body of spec's shape (drawn unless its material says otherwise)
/// that never moves by physics and has no collision response (it exerts no force, rays pass
/// through it), and whose overlaps with the world's rigid and soft bodies are found after every
/// step (ghost_overlaps). It moves with set_pose or rides on a parent (Object::attach_to); its mass
/// and kinematic flag are ignored.
AMBFPLUS_API RigidBody& add_ghost(Model& model, RigidBodySpec spec);

/// Whether a body is a ghost.
AMBFPLUS_API bool is_ghost(const RigidBody& body);

/// The bodies overlapping a ghost at the end of the last step (or when it was added), in
/// creation order: rigid bodies whose shape penetrates the ghost's (Bullet's narrow phase) and
/// soft bodies with a node inside it (tested against its convex parts; a ghost with a concave
/// mesh shape reports no soft bodies, with a warning). Throws ArgumentError for a body that is
/// not a ghost.
AMBFPLUS_API std::vector<Object*> ghost_overlaps(const RigidBody& ghost);

}  // namespace ambfplus
