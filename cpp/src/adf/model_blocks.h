#pragma once

// The blocks of a model file, one reader per kind (bodies, joints, cameras and lights, soft
// bodies, sensors and actuators; volumes and drills are volume_adf.cpp's): each turns a block into
// a plan (its spec and what is looked up later), checked before anything is created. Where a
// block's keys are Python's keywords (spaces for underscores), the spec's option table sets them,
// so a key means the same in a file and in Python.

#include <yaml-cpp/yaml.h>

#include <array>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "adf/adf_internal.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/soft_body.h"

namespace ambfplus::adf {

// ---- Shared by the block readers (model_blocks.cpp).

/// A file in the first folder that has it (exactly, or with another case), or AssetNotFound
/// listing every place looked.
std::string find_file(const Doc& doc, const std::string& where, const std::string& file,
                      const std::vector<std::string>& folders, const char* what);

/// A primitive from `shape` and `geometry` (dimensions times scale). Planes come back with the
/// pose of their z = 0 plane (from `normal` and `offset`).
std::pair<Shape, Eigen::Matrix4d> primitive(const Doc& doc, const std::string& where,
                                            const YAML::Node& shape_node,
                                            const YAML::Node& geometry, double scale);

/// A block's namespace: its `namespace` joined to base (AMBF's rules), or base.
std::string block_ns(const Doc& doc, const Context& ctx, const std::string& base,
                     const std::string& id, const YAML::Node& block);

/// `color`, `color rgba` or `color components` of a block (grey with a warning for a colour
/// name the colour table lacks).
Material material(const Doc& doc, const std::string& where, const YAML::Node& block,
                  const Context& ctx);

// ---- Blocks, one file each.

struct BodyPlan {
  std::string id;
  std::string ns;
  RigidBodySpec spec;
  std::vector<AdfPlugin> plugins;
};
/// A `bodies` block (body_adf.cpp); meshes are looked for in its own folders, then the model's.
BodyPlan plan_body(const Doc& doc, const std::string& model_hr, const std::string& model_lr,
                   const std::string& model_ns, const std::string& id, const YAML::Node& b,
                   Context& ctx);

struct JointPlan {
  std::string id;
  std::string ns;
  std::string parent, child;  // as written
  YAML::Node block;
  JointSpec spec;  // without its bodies
  std::vector<AdfPlugin> plugins;
  std::optional<SixDofAxes> six_dof;          // six dof (spring) per-axis settings
  std::optional<std::array<double, 3>> cone;  // cone twist limits
};
/// A `joints` block (joint_adf.cpp).
JointPlan plan_joint(const Doc& doc, const std::string& model_ns, const std::string& id,
                     const YAML::Node& j, Context& ctx);

/// A `soft bodies` block (soft_body_adf.cpp), its mesh found in the model's folders.
SoftBodySpec plan_soft_body(const Doc& doc, const std::string& model_lr,
                            const std::string& model_hr, const std::string& id, const YAML::Node& b,
                            Context& ctx);

struct SensorPlan {
  std::string id, ns, parent;
  YAML::Node block;
  bool actuator = false;
  ProximitySensorSpec sensor;
  ConstraintActuatorSpec act;
  std::vector<AdfPlugin> plugins;
};
/// A `sensors` or `actuators` block (sensor_adf.cpp), or nothing (with a warning) for types
/// ambfplus lacks.
std::optional<SensorPlan> plan_sensor(const Doc& doc, const std::string& model_ns, bool actuator,
                                      const std::string& id, const YAML::Node& n, Context& ctx);

// ---- Names (model_adf.cpp).

/// The one object a reference names: this file's bodies first (identifier or name), then the
/// world (exact, else a unique substring, also under the model's namespace), of one kind or, for
/// parents, any kind but joints. nullptr when none or several match; why is in `why`.
Object* find_object(World& world, const std::string& ref, const std::string& ns,
                    const std::vector<std::pair<std::string, RigidBody*>>& own,
                    std::optional<ObjectKind> kind, std::string& why);
RigidBody* find_body(World& world, const std::string& ref, const std::string& ns,
                     const std::vector<std::pair<std::string, RigidBody*>>& own, std::string& why);

// ---- Parents across files (camera_light_adf.cpp).

/// Runs attempt now; if what it names is not in the world yet, keeps it to run again when a later
/// file brings it (AMBF resolves parents across files, in any order). `missing` is the warning
/// if that never happens.
void now_or_later(Model& model, const std::string& file,
                  const std::function<std::string()>& missing, std::function<bool(World&)> attempt);

/// Attaches child to the object parent names (looked up in own, then the world) at local in
/// that object's frame, now or once it appears.
void attach_when_found(Model& model, const std::string& file, Object& child, const std::string& id,
                       const std::string& parent, const std::string& ns,
                       const std::vector<std::pair<std::string, RigidBody*>>& own,
                       const Eigen::Isometry3d& local);

}  // namespace ambfplus::adf
