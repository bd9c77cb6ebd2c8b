#include "ambfplus/scene/world.h"

#include <algorithm>

#include "ambfplus/plugin/registry.h"
#include "physics/physics_world.h"

#include <cmath>
#include <stdexcept>

#include "render/scene_renderer.h"

namespace ambfplus {

World::World(Simulator& simulator, std::string name, double time_step)
    : simulator_(&simulator),
      name_(std::move(name)),
      time_step_(time_step),
      physics_(std::make_unique<physics::PhysicsWorld>()),
      plugins_(std::make_unique<PluginRegistry>(*this)) {
  models_.push_back(std::unique_ptr<Model>(new Model(*this, name_)));
}

// The renderer releases its GL objects before the objects it drew go away, and Bullet lets go
// of bodies and joints before they are deleted. Plugins close first, while all is intact.
World::~World() {
  plugins_->close_all();
  plugins_.reset();
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

std::vector<Object*> World::lookup(const std::string& query, std::optional<ObjectKind> kind) const {
  std::vector<Object*> exact, partial;
  if (query.empty()) return exact;
  for (Object* o : objects_) {
    if (kind && o->kind() != *kind) continue;
    const std::string qualified = o->qualified_name();
    const std::string& id = o->identifier();
    if (o->name() == query || qualified == query ||
        (!id.empty() && (id == query || o->name_space() + id == query))) {
      exact.push_back(o);
    } else if (qualified.find(query) != std::string::npos ||
               (!id.empty() && (o->name_space() + id).find(query) != std::string::npos)) {
      partial.push_back(o);
    }
  }
  return exact.empty() ? partial : exact;
}

std::vector<Joint*> World::descendant_joints(const RigidBody& root) const {
  const std::vector<Joint*> joints = objects_of_kind<Joint>();
  std::vector<const RigidBody*> reached{&root};
  std::vector<bool> taken(joints.size(), false);
  // Grow the set of reached bodies until no joint adds one (closed loops end it too).
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      if (taken[i] ||
          std::find(reached.begin(), reached.end(), &joints[i]->parent()) == reached.end()) {
        continue;
      }
      taken[i] = true;
      grew = true;
      if (std::find(reached.begin(), reached.end(), &joints[i]->child()) == reached.end()) {
        reached.push_back(&joints[i]->child());
      }
    }
  }
  std::vector<Joint*> out;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (taken[i] && !joints[i]->spec().passive) out.push_back(joints[i]);
  }
  return out;
}

void World::remove_model(Model& model) {
  if (&model == models_.front().get()) {
    throw std::invalid_argument("the world's default model cannot be removed");
  }
  const auto it = std::find_if(models_.begin(), models_.end(),
                               [&](const auto& m) { return m.get() == &model; });
  if (it == models_.end()) throw std::invalid_argument("the model is not in this world");
  plugins_->close_model(model);
  for (Object* object : model.objects()) {
    plugins_->object_removed(*object);
    if (step_log_ && step_log_->logs(*object)) step_log_.reset();
  }
  ++objects_revision_;
  // Newest first: joints go before the bodies they hold.
  for (auto o = model.owned_.rbegin(); o != model.owned_.rend(); ++o) {
    Object* object = o->get();
    if (auto* joint = dynamic_cast<Joint*>(object)) physics_->remove(*joint);
    if (auto* body = dynamic_cast<RigidBody*>(object)) physics_->remove(*body);
    by_name_.erase(object->name());
    objects_.erase(std::find(objects_.begin(), objects_.end(), object));
    track_attached(object, false);
  }
  while (!model.owned_.empty()) model.owned_.pop_back();
  // Its GPU copies are keyed by addresses that may be reused.
  renderer_.reset();
  models_.erase(it);
}

int World::claim_name(const std::string& name, const char* what) {
  if (name.empty()) throw std::invalid_argument(std::string("a ") + what + " needs a name");
  if (Object* existing = find(name)) {
    throw std::invalid_argument(std::string("cannot add ") + what + " '" + name +
                                "': the world already has a " + object_kind_name(existing->kind()) +
                                " with that name");
  }
  return next_id_;
}

void World::track_attached(Object* object, bool attached) {
  const auto it = std::find(attached_.begin(), attached_.end(), object);
  if (attached && it == attached_.end()) {
    // Creation order (ids grow with it), so a child of a child follows after its parent.
    attached_.insert(
        std::upper_bound(attached_.begin(), attached_.end(), object,
                         [](const Object* a, const Object* b) { return a->id() < b->id(); }),
        object);
  } else if (!attached && it != attached_.end()) {
    attached_.erase(it);
  }
}

void World::register_object(Object* object) {
  by_name_[object->name()] = object;
  objects_.push_back(object);
  next_id_ = object->id() + 1;
  ++objects_revision_;
  plugins_->object_added(*object);
}

void World::step(std::int64_t n) {
  if (n < 0) throw std::invalid_argument("step count must be >= 0, got " + std::to_string(n));
  auto lock = lock_state();  // the lists below, then one step at a time
  std::vector<InputDevice*> devices = objects_of_kind<InputDevice>();
  std::vector<Drill*> drills = objects_of_kind<Drill>();
  std::vector<ProximitySensor*> sensors = objects_of_kind<ProximitySensor>();
  std::vector<ConstraintActuator*> actuators = objects_of_kind<ConstraintActuator>();
  std::uint64_t listed = objects_revision_;
  lock.unlock();
  for (std::int64_t s = 0; s < n; ++s) {
    lock.lock();
    const bool realtime = realtime_;
    // Polled devices sample before anything changes, so a sampler that throws leaves the world
    // as it was.
    if (!realtime) {
      for (InputDevice* d : devices) {
        Device& device = *d->device();
        if (device.polled() && step_index_ % device.poll_every() == 0) {
          device.poll(static_cast<double>(step_index_ + 1) * time_step_);
        }
      }
    }
    ++step_index_;
    // Devices first: their readings move the drills this step.
    for (InputDevice* d : devices) d->pre_step(step_index_, time());
    physics_->step(time_step_);
    for (Drill* d : drills) d->tick(time_step_, step_index_);
    for (InputDevice* d : devices) d->post_step(time_step_);
    for (Object* o : attached_) o->follow_parent();
    // Sensors see where everything ended up.
    for (ConstraintActuator* a : actuators) a->update();
    for (ProximitySensor* p : sensors) p->update();
    plugins_->physics_update(time_step_, /*native_only=*/realtime);
    if (step_log_) step_log_->record(step_index_, time());
    // Plugins may add or remove objects.
    if (objects_revision_ != listed) {
      devices = objects_of_kind<InputDevice>();
      drills = objects_of_kind<Drill>();
      sensors = objects_of_kind<ProximitySensor>();
      actuators = objects_of_kind<ConstraintActuator>();
      listed = objects_revision_;
    }
    lock.unlock();
  }
}

void World::start_step_log(const std::vector<const Object*>& objects) {
  for (const Object* o : objects) {
    if (o == nullptr || &o->world() != this) {
      throw std::invalid_argument("a step log can only log objects of its world");
    }
  }
  auto lock = lock_state();
  step_log_ = std::make_unique<StepLog>(objects);
}

void World::stop_step_log() {
  auto lock = lock_state();
  step_log_.reset();
}

StepLog World::take_step_log() {
  auto lock = lock_state();
  return step_log_ ? step_log_->take() : StepLog(std::vector<const Object*>{});
}

PluginRegistry& World::plugins() { return *plugins_; }

void World::reset_plugins() { plugins_->reset(); }

render::SceneRenderer& World::renderer() {
  auto lock = lock_state();
  if (!renderer_) renderer_ = std::make_unique<render::SceneRenderer>(*this);
  return *renderer_;
}

void World::graphics_update() {
  auto lock = lock_state();
  if (graphics_step_ != step_index_) {
    graphics_step_ = step_index_;
    plugins_->graphics_update();
  }
}

}  // namespace ambfplus
