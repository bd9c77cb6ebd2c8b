#pragma once

// Per-axis settings of joints with several degrees of freedom: six dof and six dof spring
// joints (Bullet's generic six-dof spring constraint) and cone twists.

#include <array>
#include <optional>

#include "ambfplus/export.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class Joint;

/// A six dof (spring) joint's degrees of freedom, in Bullet's order: translation along x, y,
/// z of the parent's joint frame, then rotation about x, y, z (the child's joint frame relative
/// to the parent's, as x-y-z Euler angles).
struct AMBFPLUS_API SixDofAxes {
  /// Limits per axis (m or rad). Absent: free. lower > upper also leaves the axis free, as
  /// Bullet reads it; lower == upper locks it.
  std::array<std::optional<double>, 6> lower, upper;
  /// Springs, on every axis of a six dof spring joint (none on a six dof joint): stiffness
  /// (N/m or N m/rad), damping (N s/m or N m s/rad) and rest position (m or rad).
  std::array<double, 6> stiffness{}, damping{}, equilibrium{};
};

/// SixDofAxes' keys (lower, upper: 6 limits each, None for free; stiffness, damping,
/// equilibrium: 6 values each), as Joint.six_dof takes them from Python.
AMBFPLUS_API const OptionTable<SixDofAxes>& six_dof_options();

/// Sets a six dof or six dof spring joint's limits and springs, per axis (AMBF's `joint
/// limits: {linear: {low: {x, y, z}, high: ...}, angular: ...}`, `stiffness`, `damping` and
/// `equilibrium point` as `{linear: {x, y, z}, angular: {x, y, z}}`). Throws ArgumentError for
/// another kind of joint or values that are not finite (or negative stiffness or damping).
AMBFPLUS_API void set_six_dof_axes(Joint& joint, const SixDofAxes& axes);
/// What set_six_dof_axes last gave the joint; nullopt before (then every axis is free, and a
/// six dof spring joint has one spring along z with the joint's own stiffness and damping).
AMBFPLUS_API std::optional<SixDofAxes> six_dof_axes(const Joint& joint);
/// A six dof (spring) joint's six coordinates now, in SixDofAxes' order (m and rad).
AMBFPLUS_API std::array<double, 6> six_dof_coordinates(const Joint& joint);

/// Sets a cone twist joint's limits (AMBF's `joint limits: {x, y, z}`): the twist about the
/// joint axis (x of its frame), and the swing spans about y and z (rad, each >= 0).
AMBFPLUS_API void set_cone_twist_limits(Joint& joint, double twist, double swing_y, double swing_z);

}  // namespace ambfplus
