#pragma once

// The per-axis keys of six dof, six dof spring and cone twist joint blocks.

#include <array>
#include <optional>
#include <string>

#include "adf/adf_internal.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/six_dof.h"

namespace ambfplus::adf {

/// A six dof (spring) joint block's `joint limits` ({linear, angular} x {low, high} x {x, y,
/// z}; an axis without both limits is free), and for six dof springs `stiffness`, `damping` and
/// `equilibrium point` ({linear, angular} x {x, y, z}). nullopt when the block gives none of
/// them. Keys of another form are warnings (AMBF reads zeros).
std::optional<SixDofAxes> read_six_dof_axes(const Doc& doc, const YAML::Node& joint,
                                            const std::string& id, JointType type, Context& ctx);

/// A cone twist block's `joint limits: {x, y, z}` (twist about x, swings about y and z).
std::optional<std::array<double, 3>> read_cone_twist_limits(const Doc& doc, const YAML::Node& joint,
                                                            const std::string& id, Context& ctx);

}  // namespace ambfplus::adf
