#include "ambfplus/scene/world.h"

#include "physics/physics_world.h"

#include <cmath>
#include <stdexcept>

#include "render/scene_renderer.h"

namespace ambfplus {

World::World(Simulator& simulator, std::string name, double time_step)
    : simulator_(&simulator),
      name_(std::move(name)),
      time_step_(time_step),
      physics_(std::make_unique<physics::PhysicsWorld>()) {
  models_.push_back(std::unique_ptr<Model>(new Model(*this, name_)));
}

// The renderer releases its GL objects before the objects it drew go away, and Bullet lets go
// of bodies and joints before they are deleted.
World::~World() {
  renderer_.reset();
  physics_->detach_all();
  models_.clear();
}

void World::set_gravity(const Eigen::Vector3d& g) { physics_->set_gravity(g); }

Eigen::Vector3d World::gravity() const { return physics_->gravity(); }

Model& World::add_model(const std::string& name) {
  for (const auto& m : models_) {
    if (m->name() == name) throw std::invalid_argument("a model named '" + name + "' exists");
  }
  models_.push_back(std::unique_ptr<Model>(new Model(*this, name)));
  return *models_.back();
}

std::vector<Model*> World::models() const {
  std::vector<Model*> out;
  for (const auto& m : models_) out.push_back(m.get());
  return out;
}

Object* World::find(const std::string& name) const {
  auto it = by_name_.find(name);
  return it == by_name_.end() ? nullptr : it->second;
}

std::vector<Object*> World::objects() const { return objects_; }

int World::claim_name(const std::string& name, const char* what) {
  if (name.empty()) throw std::invalid_argument(std::string("a ") + what + " needs a name");
  if (Object* existing = find(name)) {
    throw std::invalid_argument(std::string("cannot add ") + what + " '" + name +
                                "': the world already has a " + object_kind_name(existing->kind()) +
                                " with that name");
  }
  return next_id_;
}

void World::register_object(Object* object) {
  by_name_[object->name()] = object;
  objects_.push_back(object);
  next_id_ = object->id() + 1;
}

void World::step(std::int64_t n) {
  if (n < 0) throw std::invalid_argument("step count must be >= 0, got " + std::to_string(n));
  const std::vector<Drill*> drills = objects_of_kind<Drill>();
  for (std::int64_t s = 0; s < n; ++s) {
    ++step_index_;
    physics_->step(time_step_);
    for (Drill* d : drills) d->tick(time_step_, step_index_);
  }
}

render::SceneRenderer& World::renderer() {
  if (!renderer_) renderer_ = std::make_unique<render::SceneRenderer>(*this);
  return *renderer_;
}

}  // namespace ambfplus
