#include "ambfplus/scene/model.h"
#include "ambfplus/errors.h"

#include "ambfplus/scene/names.h"
#include "ambfplus/scene/world.h"

#include <stdexcept>
#include <string>

namespace ambfplus {

Model::Model(World& world, std::string name) : world_(&world), name_(std::move(name)) {}

Model::~Model() = default;

int Model::claim_name(const std::string& name, const char* what) {
  return world_->claim_name(name, name_key(object_name_space_, name), what);
}

// The world's systems hear of the object (physics builds its Bullet side and may refuse it);
// only an object they all took is kept.
Object& Model::adopt(std::unique_ptr<Object> object) {
  if (!object || &object->model() != this) {
    throw ArgumentError("model '" + name_ + "': adopt needs an object built for it");
  }
  Object& ref = *object;
  ref.name_space_ = object_name_space_;
  objects_.push_back(object.get());
  try {
    world_->register_object(object.get());
  } catch (...) {
    objects_.pop_back();
    throw;
  }
  owned_.push_back(std::move(object));
  return ref;
}

RigidBody& Model::add_body(const RigidBodySpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "body");
  // The constructor loads or builds geometry and may throw, as may physics when adopted.
  return adopt(std::unique_ptr<RigidBody>(new RigidBody(*this, spec, id)));
}

Joint& Model::add_joint(const JointSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "joint");
  return adopt(std::unique_ptr<Joint>(new Joint(*this, spec, id)));
}

Camera& Model::add_camera(const CameraSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "camera");
  return adopt(std::unique_ptr<Camera>(new Camera(*this, spec, id)));
}

Light& Model::add_light(const LightSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "light");
  int same_type = 0;
  for (const Light* l : world_->objects_of_kind<Light>()) same_type += l->type() == spec.type;
  if (same_type >= kMaxLightsPerType) {
    throw ArgumentError("cannot add light '" + spec.name + "': the world already has " +
                        std::to_string(kMaxLightsPerType) + " " + light_type_name(spec.type) +
                        " lights, the most it can draw");
  }
  return adopt(std::unique_ptr<Light>(new Light(*this, spec, id)));
}

Volume& Model::add_volume(const VolumeSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "volume");
  return adopt(std::unique_ptr<Volume>(new Volume(*this, spec, id)));
}

SoftBody& Model::add_soft_body(const SoftBodySpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "soft body");
  // The constructor reads the mesh and may throw, as may physics when adopted.
  return adopt(std::unique_ptr<SoftBody>(new SoftBody(*this, spec, id)));
}

ProximitySensor& Model::add_sensor(const ProximitySensorSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "sensor");
  return adopt(std::unique_ptr<ProximitySensor>(new ProximitySensor(*this, spec, id)));
}

ConstraintActuator& Model::add_actuator(const ConstraintActuatorSpec& spec) {
  auto lock = world_->lock_state();  // claim, build and adopt as one (thread-safety contract)
  const int id = claim_name(spec.name, "actuator");
  return adopt(std::unique_ptr<ConstraintActuator>(new ConstraintActuator(*this, spec, id)));
}

}  // namespace ambfplus
