#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class RigidBody;
namespace physics {
class PhysicsWorld;
}  // namespace physics

/// How a constraint actuator holds a body.
enum class ActuatorHold {
  kFixed,  ///< the body keeps its pose relative to the actuator (AMBF 2.0)
  /// only the point is held, the body may turn about it; `max impulse` and `tau` apply (AMBF 1.x)
  kPoint,
};
/// Parses "fixed" and "point" (any case).
AMBFPLUS_API ActuatorHold parse_actuator_hold(const std::string& name);
AMBFPLUS_API const char* actuator_hold_name(ActuatorHold hold);

/// Everything needed to create a constraint actuator: AMBF's `type: Constraint` block.
struct AMBFPLUS_API ConstraintActuatorSpec {
  std::string name;             ///< `name`
  RigidBody* parent = nullptr;  ///< `parent`: the body that holds (required)
  /// `location` {position, orientation}: the actuator frame in the parent body's frame.
  Eigen::Matrix4d location = Eigen::Matrix4d::Identity();
  double max_impulse = 10.0;   ///< `max impulse`, N s per step (point hold); AMBF 10
  double tau = 1.0;            ///< `tau`: share of the point error corrected per step; AMBF 1
  bool visible = false;        ///< `visible`; AMBF false (not drawn yet)
  double visible_size = 0.02;  ///< `visible size`, m; AMBF 0.02
  ActuatorHold hold = ActuatorHold::kFixed;  ///< ambfplus: how the body is held

  /// Throws ArgumentError naming the actuator and the value unless every value can be used (a
  /// rigid location, max impulse > 0, tau in (0, 1], visible size >= 0).
  void validate() const;
};

/// add_actuator's keyword options: location (4x4 in the parent's frame) or pose (4x4 world,
/// now; the parent must be set first), hold, max_impulse, tau, visible, visible_size.
AMBFPLUS_API const OptionTable<ConstraintActuatorSpec>& constraint_actuator_options();

/// Holds a body to its parent body at the actuator's frame on request (a gripper's grasp): a
/// Bullet constraint made by actuate() and removed by deactuate().
class AMBFPLUS_API ConstraintActuator : public Object {
 public:
  ~ConstraintActuator() override;
  ObjectKind kind() const override { return ObjectKind::kActuator; }
  const ConstraintActuatorSpec& spec() const { return spec_; }
  RigidBody& parent() const { return *spec_.parent; }

  /// Holds `body` where it is now relative to the actuator. A body already held is kept; another
  /// one is released first. Throws ArgumentError for the parent itself, a body of another
  /// world, or one physics does not move (static or kinematic).
  void actuate(RigidBody& body);
  /// Holds `body` with the actuator frame at `offset` in the body's frame (for a point hold only
  /// its position matters), pulling the body there.
  void actuate(RigidBody& body, const Eigen::Isometry3d& offset);
  /// Releases the body held (nothing when none is).
  void deactuate();
  bool is_actuated() const { return body_ != nullptr; }
  /// The body held, or nullptr.
  RigidBody* actuated_body() const { return body_; }

  /// Places the actuator (its location on the parent follows, so it moves with the parent).
  void set_pose(const Eigen::Isometry3d& pose) override;
  /// The actuator frame in the parent's frame.
  Eigen::Isometry3d location() const;
  /// Follows the parent (the world does this after each physics step).
  void update();

 private:
  friend class Model;
  friend class physics::PhysicsWorld;
  ConstraintActuator(Model& model, const ConstraintActuatorSpec& spec, int id);

  ConstraintActuatorSpec spec_;
  RigidBody* body_ = nullptr;
};

}  // namespace ambfplus
