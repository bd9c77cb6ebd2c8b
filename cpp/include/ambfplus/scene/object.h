#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus {

class Model;
class World;

/// What kind of object a scene object is.
enum class ObjectKind {
  kRigidBody,
  kJoint,
  kCamera,
  kLight,
  kVolume,
  kDrill,
  kSoftBody,
  kSensor,
  kActuator,
  kInputDevice,
};

/// Name of an ObjectKind as users see it ("body", "joint", "camera", "light", "volume", "drill",
/// "soft body", "sensor", "actuator", "input device").
AMBFPLUS_API const char* object_kind_name(ObjectKind kind);

/// Anything that lives in a world under a name unique within that world.
///
/// Objects are created by their model and live as long as their world; handles to them (in C++
/// references, in Python objects) must not outlive the world, which the bindings guarantee.
class AMBFPLUS_API Object {
 public:
  virtual ~Object();
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;

  virtual ObjectKind kind() const = 0;
  /// The name it was declared with (an ADF block's `name`, a spec's name). Unique within its
  /// namespace; objects of different namespaces may share it (two arms' "baselink").
  const std::string& name() const { return name_; }
  /// Its name unique in the world, as AMBF's client keys it: the namespace below AMBF's root
  /// "/ambf/env/" and the name ("psm1/baselink"); the bare name in the root namespace or none.
  /// Legends, recordings, exports and the live view name objects by it.
  std::string key() const;
  /// Its kind and name as messages name it: "body 'a'".
  std::string describe() const;
  /// Stable instance id (>= 1, never reused in a world); segmentation images use it.
  int id() const { return id_; }
  Model& model() const { return *model_; }
  World& world() const;

  /// World from object.
  const Eigen::Isometry3d& pose() const { return pose_; }
  virtual void set_pose(const Eigen::Isometry3d& pose) { pose_ = pose; }

  /// AMBF namespace ("/ambf/env/"), "" for objects built from Python without one.
  const std::string& name_space() const { return name_space_; }
  /// Moves it to another namespace (its key changes with it). Throws ArgumentError if the world
  /// has another object with the key it would get.
  void set_name_space(std::string ns);
  /// namespace + name, as AMBF publishes it ("/ambf/env/l1").
  std::string qualified_name() const { return name_space_ + name_; }
  /// The ADF block it came from ("BODY l1"), "" when not loaded from a file.
  const std::string& identifier() const { return identifier_; }
  void set_identifier(std::string identifier) { identifier_ = std::move(identifier); }

  /// Rides on a rigid body: after every step the pose becomes parent pose * local (cameras and
  /// lights with an ADF `parent`). nullptr detaches (the pose stays where it is).
  void attach_to(const Object* parent, const Eigen::Isometry3d& local);
  const Object* attached_to() const { return attached_to_; }
  /// Moves an attached object to its parent's pose * local (the world calls it every step).
  void follow_parent();

  /// The physics system's state of this object (a Bullet body, joint or soft body), opaque to
  /// the scene; nullptr for objects physics does not simulate. For the engine.
  ObjectState* physics_state() const { return physics_state_.get(); }
  void set_physics_state(std::unique_ptr<ObjectState> state) { physics_state_ = std::move(state); }

 protected:
  Object(Model& model, std::string name, int id);

 private:
  friend class World;
  friend class Model;
  Model* model_;
  std::string name_;
  int id_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  std::string name_space_;
  std::string identifier_;
  const Object* attached_to_ = nullptr;
  Eigen::Isometry3d local_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<ObjectState> physics_state_;
};

/// The largest |coordinate| (m) of a position that a pose, a spec or an ADF file may give: beyond
/// it neither Bullet nor the renderer keeps any precision, so such a value is a mistake.
constexpr double kMaxPosition = 1e6;

/// Throws ArgumentError unless m is a rigid transform (orthonormal rotation with det +1,
/// last row 0 0 0 1, finite) whose position is within kMaxPosition of the origin, tolerating
/// rounding of tol. The message begins with who ("body 'a'") when it is given.
AMBFPLUS_API Eigen::Isometry3d checked_pose(const Eigen::Matrix4d& m, std::string_view who = {},
                                            double tol = 1e-6);
/// checked_pose for an object's pose: the message begins with object.describe() and role
/// ("body 'a' local"), the name made only on failure (setters may run at every step).
AMBFPLUS_API Eigen::Isometry3d checked_pose(const Eigen::Matrix4d& m, const Object& object,
                                            std::string_view role = {});

}  // namespace ambfplus
