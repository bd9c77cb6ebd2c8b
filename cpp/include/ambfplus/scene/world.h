#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <functional>

#include "ambfplus/export.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/state_mutex.h"
#include "ambfplus/scene/step_log.h"
#include "ambfplus/scene/system.h"

namespace ambfplus {

class Simulator;
namespace scene {
class Attachments;
class StepLogger;
}  // namespace scene

/// Something a loader could not finish because an object it names is not in the world yet:
/// AMBF attaches a child to a parent declared in any file, loaded before or after it.
struct AMBFPLUS_API DeferredLink {
  Model* model = nullptr;   ///< the model the link belongs to; dropped if it is removed
  std::string file;         ///< the file that declared it
  std::string description;  ///< the warning if it never resolves: what waits for what
  /// Tries again: true once done (the link is then forgotten); false while what it names is
  /// still missing. It may throw (the link is then forgotten and the error passed on).
  std::function<bool(World&)> resolve;
};

/// The scene: models and their objects, the simulation clock, and the systems that step them.
///
/// A step runs the world's systems stage by stage (StepStage: device input, physics, haptics,
/// device output, attachments, actuators, sensors, plugins, logging), each stage's systems in
/// the order they were added. The world itself holds only the scene's own systems (the
/// attachments of objects riding on others, and the step log); the layer above it
/// (ambfplus/engine/engine.h) adds physics, devices, drills, the renderer and the plugins, which
/// other areas reach through find_system.
class AMBFPLUS_API World {
 public:
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const std::string& name() const { return name_; }
  Simulator& simulator() const { return *simulator_; }

  /// The model that holds objects added to the world directly.
  Model& default_model() { return *models_.front(); }
  /// Creates an empty model. Throws ArgumentError if the name is taken.
  Model& add_model(const std::string& name);
  /// Models in creation order, the default model first.
  std::vector<Model*> models() const;

  /// The object with exactly this key (Object::key: "psm1/baselink", or the bare name in AMBF's
  /// root namespace), or nullptr.
  Object* find(const std::string& name) const;
  /// The object with this id, or nullptr (ids grow with creation, so this is a search).
  Object* object_with_id(int id) const;
  /// Objects a name refers to, the way AMBF finds them, in tiers (the first that matches
  /// anything answers): 1. the full name (namespace + name, "/ambf/env/psm1/l1", or namespace +
  /// identifier) equals the query; 2. the key (Object::key, "psm1/l1", or the identifier's);
  /// 3. the bare name or identifier ("l1", "BODY l1"); 4. the full name or namespace +
  /// identifier contains it. Optionally of one kind only. One result is a match; none or
  /// several are for the caller to report.
  std::vector<Object*> lookup(const std::string& query,
                              std::optional<ObjectKind> kind = std::nullopt) const;
  /// The joints below a body, as AMBF lists a root body's joints: every joint reachable through
  /// parent-to-child links, passive ones left out, in creation order.
  std::vector<Joint*> descendant_joints(const RigidBody& root) const;
  /// Removes a model and its objects (a loader undoing a model it could not finish). Nothing may
  /// hold a handle to them, and no other model's joint may use its bodies.
  void remove_model(Model& model);
  /// All objects in creation order.
  std::vector<Object*> objects() const;

  /// Keeps a link to finish when what it names appears (resolve_deferred_links).
  void defer_link(DeferredLink link);
  /// Tries every waiting link, in the order they were deferred, until a pass resolves none;
  /// returns how many were resolved. A link that throws is dropped and the first error
  /// rethrown after the others were tried.
  int resolve_deferred_links();
  /// The links still waiting.
  const std::vector<DeferredLink>& deferred_links() const { return deferred_; }
  template <typename T>
  std::vector<T*> objects_of_kind() const;

  /// Advances the clock by n fixed steps: for each, every system's prepare() (which may cancel
  /// the step), then the clock, then the stages.
  void step(std::int64_t n = 1);
  /// Adds a system after those the world has: it runs in the stages it names after theirs and
  /// hears of objects added from now on. Throws ArgumentError for a null system.
  void add_system(std::unique_ptr<System> system);
  /// The systems in the order they hear of objects and run within a stage.
  std::vector<System*> systems() const;
  /// The first system that is a T (physics::Physics, render::Renderer, ...), or nullptr.
  template <typename T>
  T* find_system() const;
  /// Fixed step, seconds.
  double time_step() const { return time_step_; }
  /// Simulation time, seconds (step_index * time_step, without accumulated rounding).
  double time() const { return static_cast<double>(step_index_) * time_step_; }
  std::int64_t step_index() const { return step_index_; }

  /// The namespace models loaded into this world use when their files name none (AMBF's
  /// "/ambf/env/"; a world file's `namespace` sets it).
  const std::string& name_space() const { return name_space_; }
  void set_name_space(std::string ns) { name_space_ = std::move(ns); }

  /// The shader of bodies whose model and material name none (AMBF's world `shaders`); unset:
  /// the engine's own.
  const std::optional<ShaderSpec>& shader() const { return shader_; }
  void set_shader(std::optional<ShaderSpec> shader) { shader_ = std::move(shader); }

  /// Starts logging every step's state of these objects (replacing a log in progress): each
  /// object's pose and the columns its systems add (System::add_step_log_columns); the log's
  /// rows are taken with take_step_log(). Throws ArgumentError for an object of another world.
  void start_step_log(const std::vector<const Object*>& objects);
  /// Stops logging; rows not taken are dropped.
  void stop_step_log();
  /// The rows since the last take (empty without a log). Takes the state lock.
  StepLog take_step_log();
  bool logging_steps() const;

  /// Serialises changes to the scene with reads of it from other threads: each step runs under
  /// it (a real-time loop's physics thread steps while cameras capture from others), and a
  /// capture copies what it draws under it. Recursive, with priority inheritance; hold it
  /// briefly.
  std::unique_lock<StateMutex> lock_state() const {
    return std::unique_lock<StateMutex>(state_mutex_);
  }
  /// lock_state() for a short copy out of the world by a thread other than a real-time loop's
  /// (a capture's snapshot, the loop's polling thread): while a loop steps the world at
  /// SCHED_FIFO, the caller runs one priority below it until it unlocks, so no other thread
  /// of the machine preempts it while the loop may be waiting (a priority ceiling on top of
  /// the lock's inheritance, which only boosts a holder once the loop waits).
  StateCopyLock lock_state_for_copy() const {
    const int loop = realtime_priority_;
    return StateCopyLock(state_mutex_, loop > 1 ? loop - 1 : loop);
  }
  /// The state lock itself, for callers that cannot hold a unique_lock (the plugin C API).
  StateMutex& state_mutex() const { return state_mutex_; }

  /// True while a RealTimeLoop steps this world: steps then leave polled devices and plugins of
  /// other languages to the loop's low-rate thread.
  bool realtime() const { return realtime_; }
  /// Marks the world as stepped by a real-time loop; false if one already is (for RealTimeLoop).
  bool enter_realtime() { return !realtime_.exchange(true); }
  void leave_realtime() {
    realtime_priority_ = 0;
    realtime_ = false;
  }
  /// The SCHED_FIFO priority of the real-time loop stepping this world (0: none, or one
  /// without real-time scheduling); set by the loop's thread once it has its scheduling.
  int realtime_priority() const { return realtime_priority_; }
  void set_realtime_priority(int priority) { realtime_priority_ = priority; }

  /// Gives the systems their graphics update (System::graphics_update: plugins' hook), once per
  /// step; every render calls it first, under lock_state() (internal to the engine).
  void graphics_update();

 private:
  friend class Simulator;
  friend class Model;
  World(Simulator& simulator, std::string name, double time_step);
  /// The id an object named `name` (key `key`: Object::key) gets; throws ArgumentError if the
  /// name is empty or the key taken.
  int claim_name(const std::string& name, const std::string& key, const char* what);
  /// Object::set_name_space for a listed object: re-keys it, or throws if the key is taken.
  void move_to_name_space(Object& object, std::string ns);
  friend class Object;
  /// Lists an object and tells the systems; if one refuses it, it is taken out again.
  void register_object(Object* object);
  scene::Attachments& attachments() { return *attachments_; }

  Simulator* simulator_;
  std::string name_;
  double time_step_;
  std::int64_t step_index_ = 0;
  std::string name_space_ = "/ambf/env/";
  int next_id_ = 1;
  // Before the models: systems outlive the objects they hold state for.
  std::vector<std::unique_ptr<System>> systems_;
  std::vector<System*> schedule_[kStepStageCount];  // the systems of each stage, in order
  scene::Attachments* attachments_ = nullptr;
  scene::StepLogger* step_logger_ = nullptr;
  std::vector<std::unique_ptr<Model>> models_;
  std::map<std::string, Object*> by_name_;
  std::vector<Object*> objects_;
  std::vector<DeferredLink> deferred_;
  std::int64_t graphics_step_ = -1;  // the step of the last graphics update
  std::optional<ShaderSpec> shader_;
  mutable StateMutex state_mutex_;
  std::atomic<bool> realtime_{false};
  std::atomic<int> realtime_priority_{0};
};

template <typename T>
T* World::find_system() const {
  for (const auto& s : systems_) {
    if (auto* t = dynamic_cast<T*>(s.get())) return t;
  }
  return nullptr;
}

template <typename T>
std::vector<T*> World::objects_of_kind() const {
  std::vector<T*> out;
  for (Object* o : objects_) {
    if (auto* t = dynamic_cast<T*>(o)) out.push_back(t);
  }
  return out;
}

}  // namespace ambfplus
