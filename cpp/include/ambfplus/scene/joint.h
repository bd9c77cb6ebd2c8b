#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class RigidBody;
namespace physics {
class PhysicsWorld;
}  // namespace physics

/// How a joint lets its child move relative to its parent.
enum class JointType {
  kRevolute,       ///< rotation about the axis (AMBF: revolute, hinge, continuous)
  kPrismatic,      ///< translation along the axis (prismatic, slider)
  kFixed,          ///< no relative motion
  kLinearSpring,   ///< translation along the axis against a spring (spring, linear spring)
  kTorsionSpring,  ///< rotation about the axis against a spring (torsion/torsional/angular spring)
  kP2P,            ///< the pivots coincide, any rotation (p2p)
  kConeTwist,      ///< rotation within a cone about the axis plus a twist (cone twist)
  kSixDof,         ///< all six degrees of freedom, within the limits (six dof)
  kSixDofSpring,   ///< six degrees of freedom with a spring on the axis (six dof spring)
};
/// Parses AMBF's joint type names (any case, spaces or underscores; `continuous` is a revolute
/// joint without limits).
AMBFPLUS_API JointType parse_joint_type(const std::string& name);
AMBFPLUS_API const char* joint_type_name(JointType type);

/// What a joint controller's output drives.
enum class ControlOutput {
  kEffort,    ///< torque or force on the bodies
  kVelocity,  ///< the joint motor's target velocity
};
/// Parses "effort" (or "force") and "velocity", any case.
AMBFPLUS_API ControlOutput parse_control_output(const std::string& name);
AMBFPLUS_API const char* control_output_name(ControlOutput output);

/// A P/I/D controller of a joint's position (AMBF: absent => P 10, I 0, D 1, velocity output;
/// declared => effort output). With effort output, effort = P e + I sum(e dt) - D v. With
/// velocity output the motor's target v solves v = P e + I sum(e dt) - D v (the D term taken at
/// the velocity the motor is about to reach, so the loop does not ring).
struct AMBFPLUS_API JointController {
  double p = 10.0;
  double i = 0.0;
  double d = 1.0;
  ControlOutput output = ControlOutput::kVelocity;

  /// Throws ArgumentError (naming `who`) unless the gains are finite.
  void validate(const std::string& who) const;
};

/// A controller's keys: p, i, d and output.
AMBFPLUS_API const OptionTable<JointController>& joint_controller_options();

/// Everything needed to create a joint. Pivots and axes are in each body's own frame.
struct AMBFPLUS_API JointSpec {
  std::string name;
  RigidBody* parent = nullptr;
  RigidBody* child = nullptr;
  JointType type = JointType::kRevolute;
  Eigen::Vector3d parent_pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d parent_axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d child_pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d child_axis = Eigen::Vector3d::UnitZ();
  double offset = 0.0;  ///< the parent frame's turn about the axis (rad)
  /// AMBF's `offset` (or `child offset`): the child's joint frame is turned by -child_offset about
  /// its axis, so a child exported at joint angle `child_offset` from the parent's frame sits at
  /// position 0 (rad).
  double child_offset = 0.0;
  std::optional<double> lower, upper;  ///< limits, rad or m
  double damping = 0.0;                ///< N m s/rad or N s/m
  double stiffness = 0.0;              ///< springs: N m/rad or N/m
  double equilibrium = 0.0;            ///< springs: rest position
  double max_motor_impulse = 0.1;      ///< N m s (or N s) per step
  double erp = 0.1;
  double cfm = 0.1;
  JointController controller;
  bool passive = false;  ///< not listed among its root body's joints (AMBF), not controlled
  bool ignore_inter_collision = true;  ///< parent and child do not collide
  /// Given as AMBF's `continuous` type (a revolute joint): it takes no limits.
  bool continuous = false;

  /// Throws ArgumentError naming the joint and the value unless every value can be used
  /// (finite pivots, non-zero axes, ordered limits, gains >= 0); its bodies are the
  /// constructor's to check.
  void validate() const;
};

/// add_joint's keyword options: type, parent_pivot, parent_axis, child_pivot, child_axis,
/// offset, child_offset, lower, upper, damping, stiffness, equilibrium, max_motor_impulse, erp,
/// cfm, controller ({p, i, d, output}; declared, it drives efforts unless told otherwise),
/// passive, ignore_inter_collision.
AMBFPLUS_API const OptionTable<JointSpec>& joint_options();

/// A joint between two bodies of the same world. Position 0 is where the parent's and the child's
/// joint frames coincide; positive is a right-handed turn (or a move) of the child about (along)
/// the parent's axis.
class AMBFPLUS_API Joint : public Object {
 public:
  /// What the joint is being asked to do.
  enum class Command { kNone, kPosition, kVelocity, kEffort };

  ~Joint() override;
  ObjectKind kind() const override { return ObjectKind::kJoint; }
  const JointSpec& spec() const { return spec_; }
  JointType type() const { return spec_.type; }
  RigidBody& parent() const { return *spec_.parent; }
  RigidBody& child() const { return *spec_.child; }

  /// Joint position (rad or m) and velocity (rad/s or m/s); 0 for joints without one axis.
  double position() const;
  double velocity() const;
  /// The effort the joint applied in the last step (controller or command), N m or N.
  double effort() const { return effort_; }

  /// Drive to a position with the joint's controller.
  void set_position(double target);
  /// Drive at a velocity with the joint's motor.
  void set_velocity(double target);
  /// Apply an effort every step.
  void set_effort(double effort);
  /// Stop commanding (the joint moves freely, with its damping and spring).
  void release();
  Command command() const { return command_; }
  double command_value() const { return target_; }
  void set_controller(const JointController& controller);
  void set_limits(std::optional<double> lower, std::optional<double> upper);
  void set_damping(double damping);

 private:
  friend class Model;
  friend class physics::PhysicsWorld;
  Joint(Model& model, const JointSpec& spec, int id);

  JointSpec spec_;
  Command command_ = Command::kNone;
  double target_ = 0.0;
  double integral_ = 0.0;
  double effort_ = 0.0;
};

}  // namespace ambfplus
