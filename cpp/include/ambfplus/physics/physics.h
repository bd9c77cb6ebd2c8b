#pragma once

// The physics system's public face: what the scene and other areas ask of a world's physics.
// Bullet sits behind it (cpp/src/physics); no public header names a Bullet type.

#include <memory>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus {

class World;

namespace physics {

/// A world's physics: rigid and soft bodies, joints and their controllers, constraint
/// actuators and proximity sensors, stepped in the stages kPhysics, kActuators and kSensors.
/// It takes objects of those kinds into Bullet as they join the world (refusing geometry Bullet
/// cannot simulate) and out again as they leave.
class AMBFPLUS_API Physics : public System {
 public:
  /// m/s^2; throws ArgumentError unless finite.
  virtual void set_gravity(const Eigen::Vector3d& gravity) = 0;
  virtual Eigen::Vector3d gravity() const = 0;
};

/// The physics of a world (AMBF's default gravity, 0, 0, -9.8).
AMBFPLUS_API std::unique_ptr<Physics> make_physics(World& world);
/// A world's physics system (engine::install_systems adds it). Throws StateError for a world
/// without one.
AMBFPLUS_API Physics& physics_of(const World& world);

}  // namespace physics
}  // namespace ambfplus
