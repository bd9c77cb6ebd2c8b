#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/light.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/soft_body.h"
#include "ambfplus/scene/volume.h"

namespace ambfplus {

class World;

/// A group of objects loaded or built together (an AMBF multibody file, or the world's own
/// objects). Names are unique across the whole world, not only within a model.
class AMBFPLUS_API Model {
 public:
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const std::string& name() const { return name_; }
  World& world() const { return *world_; }
  /// Objects in creation order.
  const std::vector<Object*>& objects() const { return objects_; }

  /// The shader of its bodies that name none (AMBF's model `shaders`); unset: the world's. An
  /// empty spec is the engine's own shader.
  const std::optional<ShaderSpec>& shader() const { return shader_; }
  void set_shader(std::optional<ShaderSpec> shader) { shader_ = std::move(shader); }

  /// Creates a body. Throws ArgumentError for a bad spec or a taken name, AssetNotFound
  /// or ConfigError for a mesh that cannot be read.
  RigidBody& add_body(const RigidBodySpec& spec);
  /// Creates a joint between two bodies of the world. Throws ArgumentError for a bad spec
  /// or a taken name.
  Joint& add_joint(const JointSpec& spec);
  /// Creates a camera. Throws ArgumentError for a bad spec or a taken name.
  Camera& add_camera(const CameraSpec& spec);
  /// Creates a light. Throws ArgumentError for a bad spec or a taken name.
  Light& add_light(const LightSpec& spec);
  /// Places a volume. Throws ArgumentError for a bad spec or a taken name.
  Volume& add_volume(const VolumeSpec& spec);
  /// Creates a soft body from a mesh file. Throws ArgumentError for a bad spec or a taken
  /// name, AssetNotFound or ConfigError for a mesh that cannot be read.
  SoftBody& add_soft_body(const SoftBodySpec& spec);
  /// Creates a proximity sensor on a rigid body of the world. Throws ArgumentError for a
  /// bad spec or a taken name.
  ProximitySensor& add_sensor(const ProximitySensorSpec& spec);
  /// Creates a constraint actuator on a rigid body of the world. Throws ArgumentError for
  /// a bad spec or a taken name.
  ConstraintActuator& add_actuator(const ConstraintActuatorSpec& spec);

  /// The namespace objects this model makes from now on are in ("" at first: Python's objects;
  /// a model file's loader sets its `namespace`). Their keys (Object::key) must be free.
  void set_object_name_space(std::string ns) { object_name_space_ = std::move(ns); }
  const std::string& object_name_space() const { return object_name_space_; }

  /// For objects of kinds defined above the scene (haptics' drills and input devices): the id
  /// an object named `name` gets. Throws ArgumentError if the name is empty or taken (`what`
  /// names the kind in the message).
  int claim_name(const std::string& name, const char* what);
  /// Keeps an object built for this model with claim_name's id: the world's systems hear of it
  /// (physics may refuse it: the error is passed on and the object is not kept).
  Object& adopt(std::unique_ptr<Object> object);
  /// adopt, giving the object back as its own type.
  template <typename T>
  T& adopt(std::unique_ptr<T> object) {
    T& ref = *object;
    adopt(std::unique_ptr<Object>(std::move(object)));
    return ref;
  }

 private:
  friend class World;
  Model(World& world, std::string name);

  World* world_;
  std::string name_;
  std::string object_name_space_;
  std::vector<std::unique_ptr<Object>> owned_;
  std::vector<Object*> objects_;
  std::optional<ShaderSpec> shader_;
};

}  // namespace ambfplus
