#pragma once

// Objects a plugin creates through the C API (ambfplus_world_add), from keyword options named
// as ambfplus's Python add_body and add_drill name them.

#include <optional>
#include <string>
#include <vector>

namespace ambfplus {

class Drill;
class Model;
class RigidBody;

namespace plugin {

/// One keyword: numbers or a text.
struct Option {
  std::string key;
  std::vector<double> values;
  std::optional<std::string> text;
};

/// A body: shape (box, sphere, cylinder, capsule, cone, plane, none; or mesh with `mesh` and
/// `scale`), size, radius, height, axis, mass, kinematic, collision, color, visible, pose.
RigidBody& add_body(Model& model, const std::string& name, const std::vector<Option>& options);
/// A ghost object (ambfplus::add_ghost): a body's options; mass and kinematic are ignored.
RigidBody& add_ghost(Model& model, const std::string& name, const std::vector<Option>& options);
/// A drill: volume (a volume's name), burr_diameters, burr, cursors, spacing, shaft_radii,
/// stiffness, damping, max_force, soft_start, removal (physical or compatible), cutting_rate,
/// voxels_per_step, pose.
Drill& add_drill(Model& model, const std::string& name, const std::vector<Option>& options);

}  // namespace plugin
}  // namespace ambfplus
