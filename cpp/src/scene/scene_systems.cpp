#include "scene/scene_systems.h"

#include <algorithm>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::scene {

void Attachments::track(Object* object, bool attached) {
  const auto it = std::find(riders_.begin(), riders_.end(), object);
  if (attached && it == riders_.end()) {
    riders_.insert(
        std::upper_bound(riders_.begin(), riders_.end(), object,
                         [](const Object* a, const Object* b) { return a->id() < b->id(); }),
        object);
  } else if (!attached && it != riders_.end()) {
    riders_.erase(it);
  }
}

void Attachments::follow(const Object& moved) {
  for (Object* o : riders_) {
    if (o->attached_to() == &moved) {
      o->follow_parent();
      follow(*o);  // parent cycles are refused by Object::attach_to
    }
  }
}

void Attachments::run(StepStage, const StepContext&) {
  for (Object* o : riders_) o->follow_parent();
}

void StepLogger::object_removed(Object& object) {
  if (log_ && log_->logs(object)) log_.reset();
}

void StepLogger::run(StepStage, const StepContext& context) {
  if (!log_) return;
  log_->record(context.step, context.time);
  if (log_->values() > kMaxValues) log_->drop_oldest(log_->rows() / 2);
}

void StepLogger::start(const std::vector<const Object*>& objects) {
  std::vector<StepLogColumns> columns;
  for (const Object* o : objects) {
    columns.emplace_back(*o);
    for (System* s : world_.systems()) s->add_step_log_columns(*o, columns.back());
  }
  log_ = std::make_unique<StepLog>(std::move(columns));
}

StepLog StepLogger::take() { return log_ ? log_->take() : StepLog(std::vector<StepLogColumns>{}); }

}  // namespace ambfplus::scene
