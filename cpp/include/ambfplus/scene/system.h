#pragma once

// Systems: the parts of the engine that take part in a world's steps (physics, devices, drills,
// attachments, actuators, sensors, plugins, the step log) and in its objects' lives (the
// renderer). The scene defines the interface, runs it and has two systems of its own (the
// attachments and the step log); the others live in the areas above it, and ambfplus/engine adds
// them to a world. World::step runs them stage by stage in the order below; cpp/README.md
// ("World steps") says what each stage sees.

#include <cstdint>

#include "ambfplus/export.h"

namespace ambfplus {

class Model;
class Object;
class StepLogColumns;
class World;

/// The stages of a world step, in the order they run.
enum class StepStage : int {
  kDeviceInput,   ///< input devices are read; their readings move the drills' goals
  kPhysics,       ///< Bullet steps bodies, joints and soft bodies; poses come back
  kHaptics,       ///< drills: cursors against the volume and bodies, forces, removal
  kDeviceOutput,  ///< the drills' forces go back to the devices
  kAttachments,   ///< objects riding on a parent follow it
  kActuators,     ///< constraint actuators hold or let go
  kSensors,       ///< sensors see where everything ended up
  kPlugins,       ///< plugins' physics_update: the state the step produced
  kLogging,       ///< the step log records the step
};
/// Number of step stages; stage s is the bit 1 << s of System::stages().
inline constexpr int kStepStageCount = 9;
/// "device input", "physics", "haptics", ...
AMBFPLUS_API const char* step_stage_name(StepStage stage);
/// The bit of a stage in System::stages().
inline constexpr unsigned stage_bit(StepStage stage) { return 1u << static_cast<int>(stage); }

/// What one step gives the systems.
struct StepContext {
  double dt = 0.0;        ///< s, the world's fixed step
  std::int64_t step = 0;  ///< the step being made (the world's index after it)
  double time = 0.0;      ///< s, the simulation time after it
  bool realtime = false;  ///< stepped by a RealTimeLoop: leave other languages to its slow thread
};

/// Engine-side state a system keeps on an object (a Bullet body, say), deleted with the object
/// through this base: the object needs to know nothing of it.
class AMBFPLUS_API ObjectState {
 public:
  virtual ~ObjectState();
};

/// A part of the engine that takes part in a world's steps and hears of its objects. A world
/// holds its systems from creation to destruction; they are called under its state lock.
class AMBFPLUS_API System {
 public:
  virtual ~System();
  /// For messages: "physics", "drills", ...
  virtual const char* name() const = 0;
  /// The stages it runs in (stage_bit of each); 0 for a system that only hears of objects.
  virtual unsigned stages() const = 0;
  /// An object joined the world (it is findable by name already). Throwing refuses it: the
  /// systems told before hear object_removed and the object is not kept.
  virtual void object_added(Object& object) {}
  /// An object is about to leave the world (it is still whole).
  virtual void object_removed(Object& object) {}
  /// Before the clock advances; throwing cancels the step with the world as it was.
  virtual void prepare(const StepContext& context) {}
  /// Its part of a step in one of its stages.
  virtual void run(StepStage stage, const StepContext& context) {}
  /// A model is about to be removed (World::remove_model), before any of its objects: let go of
  /// what belongs to the model as a whole (plugins of model scope close).
  virtual void model_removing(Model& model) {}
  /// Before a render copies the world, at most once per step (World::graphics_update).
  virtual void graphics_update() {}
  /// Adds what it logs of an object to a step log (World::start_step_log): columns after the
  /// object's pose, or the pose left out (an input device has none of its own).
  virtual void add_step_log_columns(const Object& object, StepLogColumns& columns) const {}
  /// The world is going away, still whole: finish what needs it whole (plugins close). Every
  /// system hears this, in the reverse of the order they were added, before any detach_all.
  virtual void world_closing() {}
  /// The world is going away: let go of every object (they are destroyed next).
  virtual void detach_all() {}
};

}  // namespace ambfplus
