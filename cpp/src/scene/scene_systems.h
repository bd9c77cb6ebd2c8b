#pragma once

// The scene's own systems: objects riding on a parent, and the step log.

#include <memory>
#include <vector>

#include "ambfplus/scene/step_log.h"
#include "ambfplus/scene/system.h"

namespace ambfplus::scene {

/// Objects riding on a parent (Object::attach_to), moved after physics and the drills in the
/// stage kAttachments, in creation order (a child of a child follows after its parent).
class Attachments : public System {
 public:
  const char* name() const override { return "attachments"; }
  unsigned stages() const override { return stage_bit(StepStage::kAttachments); }
  void object_removed(Object& object) override { track(&object, false); }
  void run(StepStage stage, const StepContext& context) override;
  void detach_all() override { riders_.clear(); }
  /// Starts or stops moving an object with its parent.
  void track(Object* object, bool attached);
  /// Moves the objects riding on `moved`, and theirs in turn, to where it now is (an object
  /// attached after its riders were: a camera's eyes when the camera is put on a body).
  void follow(const Object& moved);

 private:
  std::vector<Object*> riders_;
};

/// The step log (World::start_step_log): a row after every step, in the stage kLogging. Rows
/// not taken are capped at kMaxValues values in all; beyond that the oldest half is dropped
/// (and counted), so a log nobody drains cannot grow without end.
class StepLogger : public System {
 public:
  /// Logs the objects of this world, with the columns its systems add.
  explicit StepLogger(const World& world) : world_(world) {}
  /// About 16 MB of doubles: 5 minutes of a drill and a device at 1 kHz.
  static constexpr std::size_t kMaxValues = std::size_t{1} << 21;
  const char* name() const override { return "step log"; }
  unsigned stages() const override { return stage_bit(StepStage::kLogging); }
  void object_removed(Object& object) override;
  void run(StepStage stage, const StepContext& context) override;
  void detach_all() override { log_.reset(); }

  void start(const std::vector<const Object*>& objects);
  void stop() { log_.reset(); }
  StepLog take();
  bool logging() const { return static_cast<bool>(log_); }

 private:
  const World& world_;
  std::unique_ptr<StepLog> log_;
};

}  // namespace ambfplus::scene
