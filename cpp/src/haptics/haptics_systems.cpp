#include <algorithm>
#include <vector>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"
#include "ambfplus/haptics/systems.h"

namespace ambfplus::haptics {
namespace {

template <typename T>
void erase(std::vector<T*>& list, const Object& object) {
  list.erase(std::remove(list.begin(), list.end(), &object), list.end());
}

class DeviceSystem : public System {
 public:
  const char* name() const override { return "devices"; }
  unsigned stages() const override {
    return stage_bit(StepStage::kDeviceInput) | stage_bit(StepStage::kDeviceOutput);
  }
  void object_added(Object& object) override {
    if (object.kind() == ObjectKind::kInputDevice) {
      devices_.push_back(static_cast<InputDevice*>(&object));
    }
  }
  void object_removed(Object& object) override { erase(devices_, object); }
  void detach_all() override { devices_.clear(); }

  // Polled devices sample before anything changes, so a sampler that throws leaves the world
  // as it was.
  void prepare(const StepContext& context) override {
    if (context.realtime) return;
    for (InputDevice* d : devices_) {
      Device& device = *d->device();
      if (device.polled() && (context.step - 1) % device.poll_every() == 0) {
        device.poll(context.time);
      }
    }
  }

  void run(StepStage stage, const StepContext& context) override {
    if (stage == StepStage::kDeviceInput) {
      for (InputDevice* d : devices_) d->pre_step(context.step, context.time);
    } else {
      for (InputDevice* d : devices_) d->post_step(context.dt);
    }
  }

 private:
  std::vector<InputDevice*> devices_;
};

class DrillSystem : public System {
 public:
  const char* name() const override { return "drills"; }
  unsigned stages() const override { return stage_bit(StepStage::kHaptics); }
  void object_added(Object& object) override {
    if (object.kind() == ObjectKind::kDrill) drills_.push_back(static_cast<Drill*>(&object));
    // The bodies a drill's cursors meet changed.
    if (object.kind() == ObjectKind::kRigidBody) {
      for (Drill* d : drills_) d->bodies_changed();
    }
  }
  void object_removed(Object& object) override {
    erase(drills_, object);
    if (object.kind() == ObjectKind::kRigidBody) {
      for (Drill* d : drills_) d->bodies_changed();
    }
  }
  void detach_all() override { drills_.clear(); }
  void run(StepStage, const StepContext& context) override {
    for (Drill* d : drills_) d->tick(context.dt, context.step);
  }

 private:
  std::vector<Drill*> drills_;
};

}  // namespace

std::unique_ptr<System> make_device_system() { return std::make_unique<DeviceSystem>(); }

std::unique_ptr<System> make_drill_system() { return std::make_unique<DrillSystem>(); }

}  // namespace ambfplus::haptics
