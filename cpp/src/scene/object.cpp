#include "ambfplus/scene/object.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ambfplus/scene/model.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/world.h"
#include "scene/scene_systems.h"

namespace ambfplus {

const char* object_kind_name(ObjectKind kind) {
  switch (kind) {
    case ObjectKind::kRigidBody:
      return "body";
    case ObjectKind::kJoint:
      return "joint";
    case ObjectKind::kCamera:
      return "camera";
    case ObjectKind::kLight:
      return "light";
    case ObjectKind::kVolume:
      return "volume";
    case ObjectKind::kDrill:
      return "drill";
    case ObjectKind::kSoftBody:
      return "soft body";
    case ObjectKind::kSensor:
      return "sensor";
    case ObjectKind::kActuator:
      return "actuator";
    case ObjectKind::kInputDevice:
      return "input device";
  }
  return "object";
}

Object::Object(Model& model, std::string name, int id)
    : model_(&model), name_(std::move(name)), id_(id) {}

Object::~Object() = default;

World& Object::world() const { return model_->world(); }

std::string Object::key() const { return name_key(name_space_, name_); }

void Object::set_name_space(std::string ns) {
  World& w = world();
  if (w.find(key()) == this) {
    w.move_to_name_space(*this, std::move(ns));
  } else {
    name_space_ = std::move(ns);  // not listed yet (being built)
  }
}

std::string Object::describe() const {
  return std::string(object_kind_name(kind())) + " '" + key() + "'";
}

void Object::attach_to(const Object* parent, const Eigen::Isometry3d& local) {
  std::string chain = name_;
  for (const Object* p = parent; p != nullptr; p = p->attached_to_) {
    chain += " -> " + p->name_;
    if (p == this) {
      throw ArgumentError("'" + name_ + "' cannot ride on '" + parent->name_ +
                          "': that makes a parent cycle " + chain);
    }
  }
  world().attachments().track(this, parent != nullptr);
  attached_to_ = parent;
  local_ = local;
  follow_parent();
  world().attachments().follow(*this);  // its own riders come along now, not at the next step
}

void Object::follow_parent() {
  if (attached_to_ != nullptr) set_pose(attached_to_->pose() * local_);
}

Eigen::Isometry3d checked_pose(const Eigen::Matrix4d& m, std::string_view who, double tol) {
  const auto fail = [&](const std::string& what) {
    throw ArgumentError(who.empty() ? what : std::string(who) + ": " + what);
  };
  if (!m.allFinite()) fail("pose has non-finite entries");
  const Eigen::RowVector4d last = m.row(3);
  if ((last - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > tol) {
    std::ostringstream s;
    s << "pose must have last row [0 0 0 1], got [" << last << "]";
    fail(s.str());
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orthonormality =
      (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality > tol || r.determinant() < 0) {
    fail("pose must be a rigid transform: its 3x3 block must be a rotation (orthonormal, det +1)");
  }
  const Eigen::Vector3d position = m.topRightCorner<3, 1>();
  if (position.cwiseAbs().maxCoeff() > kMaxPosition) {
    std::ostringstream s;
    s << "position (" << position.transpose() << ") is beyond " << kMaxPosition
      << " m of the origin, where nothing keeps its precision";
    fail(s.str());
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.matrix() = m;
  pose.matrix().row(3) << 0, 0, 0, 1;
  return pose;
}

Eigen::Isometry3d checked_pose(const Eigen::Matrix4d& m, const Object& object,
                               std::string_view role) {
  try {
    return checked_pose(m);
  } catch (const ArgumentError& e) {
    std::string who = object.describe();
    if (!role.empty()) who += " " + std::string(role);
    throw ArgumentError(who + ": " + e.what());
  }
}

}  // namespace ambfplus
