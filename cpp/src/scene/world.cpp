#include "ambfplus/scene/world.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/names.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/scene_systems.h"

namespace ambfplus {

const char* step_stage_name(StepStage stage) {
  switch (stage) {
    case StepStage::kDeviceInput:
      return "device input";
    case StepStage::kPhysics:
      return "physics";
    case StepStage::kHaptics:
      return "haptics";
    case StepStage::kDeviceOutput:
      return "device output";
    case StepStage::kAttachments:
      return "attachments";
    case StepStage::kActuators:
      return "actuators";
    case StepStage::kSensors:
      return "sensors";
    case StepStage::kPlugins:
      return "plugins";
    case StepStage::kLogging:
      return "logging";
  }
  return "?";
}

ObjectState::~ObjectState() = default;
System::~System() = default;

World::World(Simulator& simulator, std::string name, double time_step)
    : simulator_(&simulator), name_(std::move(name)), time_step_(time_step) {
  models_.push_back(std::unique_ptr<Model>(new Model(*this, name_)));
  // The scene's own systems; the engine adds the others after them (engine::install_systems).
  auto attachments = std::make_unique<scene::Attachments>();
  attachments_ = attachments.get();
  add_system(std::move(attachments));
  auto logger = std::make_unique<scene::StepLogger>(*this);
  step_logger_ = logger.get();
  add_system(std::move(logger));
}

// What needs the world whole finishes first (plugins close); then every system lets go of the
// objects (the renderer its GL objects, Bullet its bodies and joints) before they are deleted.
World::~World() {
  for (auto it = systems_.rbegin(); it != systems_.rend(); ++it) (*it)->world_closing();
  for (auto it = systems_.rbegin(); it != systems_.rend(); ++it) (*it)->detach_all();
  models_.clear();
}

void World::add_system(std::unique_ptr<System> system) {
  auto lock = lock_state();  // the thread-safety contract
  if (!system) throw ArgumentError("world '" + name_ + "': add_system needs a system");
  for (int s = 0; s < kStepStageCount; ++s) {
    if (system->stages() & (1u << s)) schedule_[s].push_back(system.get());
  }
  systems_.push_back(std::move(system));
}

std::vector<System*> World::systems() const {
  std::vector<System*> out;
  for (const auto& s : systems_) out.push_back(s.get());
  return out;
}

Model& World::add_model(const std::string& name) {
  auto lock = lock_state();  // the thread-safety contract
  for (const auto& m : models_) {
    if (m->name() == name) throw ArgumentError("a model named '" + name + "' exists");
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

Object* World::object_with_id(int id) const {
  const auto it = std::lower_bound(objects_.begin(), objects_.end(), id,
                                   [](const Object* o, int wanted) { return o->id() < wanted; });
  return it != objects_.end() && (*it)->id() == id ? *it : nullptr;
}

std::vector<Object*> World::lookup(const std::string& query, std::optional<ObjectKind> kind) const {
  // The tiers, first that matches wins: full names, keys, bare names, then containing.
  std::vector<Object*> full, keyed, bare, partial;
  if (query.empty()) return full;
  for (Object* o : objects_) {
    if (kind && o->kind() != *kind) continue;
    const std::string qualified = o->qualified_name();
    const std::string& id = o->identifier();
    const std::string qualified_id = id.empty() ? std::string() : o->name_space() + id;
    if (qualified == query || (!id.empty() && qualified_id == query)) {
      full.push_back(o);
    } else if (o->key() == query || (!id.empty() && name_key(o->name_space(), id) == query)) {
      keyed.push_back(o);
    } else if (o->name() == query || (!id.empty() && id == query)) {
      bare.push_back(o);
    } else if (qualified.find(query) != std::string::npos ||
               (!id.empty() && qualified_id.find(query) != std::string::npos)) {
      partial.push_back(o);
    }
  }
  for (auto* tier : {&full, &keyed, &bare}) {
    if (!tier->empty()) return std::move(*tier);
  }
  return partial;
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
  auto lock = lock_state();  // the thread-safety contract
  if (&model == models_.front().get()) {
    throw ArgumentError("the world's default model cannot be removed");
  }
  const auto it = std::find_if(models_.begin(), models_.end(),
                               [&](const auto& m) { return m.get() == &model; });
  if (it == models_.end()) throw ArgumentError("the model is not in this world");
  for (auto sys = systems_.rbegin(); sys != systems_.rend(); ++sys) (*sys)->model_removing(model);
  deferred_.erase(std::remove_if(deferred_.begin(), deferred_.end(),
                                 [&](const DeferredLink& l) { return l.model == &model; }),
                  deferred_.end());
  // Newest first (joints go before the bodies they hold), each heard of by the systems in the
  // reverse of the order they took it in, while it is whole.
  for (auto o = model.owned_.rbegin(); o != model.owned_.rend(); ++o) {
    Object* object = o->get();
    for (auto sys = systems_.rbegin(); sys != systems_.rend(); ++sys) {
      (*sys)->object_removed(*object);
    }
    by_name_.erase(object->key());
    objects_.erase(std::find(objects_.begin(), objects_.end(), object));
  }
  while (!model.owned_.empty()) model.owned_.pop_back();
  models_.erase(it);
}

void World::defer_link(DeferredLink link) {
  if (!link.resolve) throw ArgumentError("a deferred link needs a resolve function");
  deferred_.push_back(std::move(link));
}

int World::resolve_deferred_links() {
  int resolved = 0;
  std::exception_ptr first_error;
  // A link resolved may be the parent another one waits for: go round until nothing changes.
  for (bool progress = true; progress && !deferred_.empty();) {
    progress = false;
    std::vector<DeferredLink> waiting;
    waiting.swap(deferred_);
    for (DeferredLink& link : waiting) {
      bool done = false;
      try {
        done = link.resolve(*this);
      } catch (...) {
        if (!first_error) first_error = std::current_exception();
        done = true;
      }
      if (done) {
        ++resolved;
        progress = true;
      } else {
        deferred_.push_back(std::move(link));
      }
    }
  }
  if (first_error) std::rethrow_exception(first_error);
  return resolved;
}

int World::claim_name(const std::string& name, const std::string& key, const char* what) {
  if (name.empty()) throw ArgumentError(std::string("a ") + what + " needs a name");
  if (Object* existing = find(key)) {
    throw ArgumentError(std::string("cannot add ") + what + " '" + key +
                        "': the world already has a " + object_kind_name(existing->kind()) +
                        " with that name");
  }
  return next_id_;
}

void World::move_to_name_space(Object& object, std::string ns) {
  auto lock = lock_state();
  const std::string old_key = object.key();
  const std::string new_key = name_key(ns, object.name());
  if (new_key != old_key) {
    if (Object* other = find(new_key)) {
      throw ArgumentError("cannot move " + object.describe() + " to namespace '" + ns +
                          "': the world already has a " + object_kind_name(other->kind()) + " '" +
                          new_key + "'");
    }
    by_name_.erase(old_key);
    by_name_[new_key] = &object;
  }
  object.name_space_ = std::move(ns);
}

void World::register_object(Object* object) {
  by_name_[object->key()] = object;
  objects_.push_back(object);
  next_id_ = object->id() + 1;
  std::size_t told = 0;
  try {
    for (; told < systems_.size(); ++told) systems_[told]->object_added(*object);
  } catch (...) {
    while (told-- > 0) systems_[told]->object_removed(*object);
    by_name_.erase(object->key());
    objects_.pop_back();
    throw;
  }
}

void World::step(std::int64_t n) {
  if (n < 0) throw ArgumentError("step count must be >= 0, got " + std::to_string(n));
  for (std::int64_t s = 0; s < n; ++s) {
    auto lock = lock_state();
    StepContext context;
    context.dt = time_step_;
    context.step = step_index_ + 1;
    context.time = static_cast<double>(context.step) * time_step_;
    context.realtime = realtime_;
    for (const auto& system : systems_) system->prepare(context);
    ++step_index_;
    for (int stage = 0; stage < kStepStageCount; ++stage) {
      // By index: a plugin may add systems' objects (not systems) during its stage.
      const std::vector<System*>& systems = schedule_[stage];
      for (std::size_t i = 0; i < systems.size(); ++i) {
        systems[i]->run(static_cast<StepStage>(stage), context);
      }
    }
  }
}

void World::start_step_log(const std::vector<const Object*>& objects) {
  for (const Object* o : objects) {
    if (o == nullptr || &o->world() != this) {
      throw ArgumentError("a step log can only log objects of its world");
    }
  }
  auto lock = lock_state();
  step_logger_->start(objects);
}

void World::stop_step_log() {
  auto lock = lock_state();
  step_logger_->stop();
}

StepLog World::take_step_log() {
  auto lock = lock_state();
  return step_logger_->take();
}

bool World::logging_steps() const { return step_logger_->logging(); }

void World::graphics_update() {
  auto lock = lock_state();
  if (graphics_step_ != step_index_) {
    graphics_step_ = step_index_;
    for (const auto& system : systems_) system->graphics_update();
  }
}

}  // namespace ambfplus
