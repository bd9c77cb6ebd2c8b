#include <algorithm>
#include <limits>
#include <vector>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"
#include "ambfplus/haptics/systems.h"
#include "ambfplus/scene/step_log.h"

namespace ambfplus::haptics {
namespace {

template <typename T>
void erase(std::vector<T*>& list, const Object& object) {
  list.erase(std::remove(list.begin(), list.end(), &object), list.end());
}

void push(std::vector<double>& out, const Eigen::Vector3d& v) {
  out.insert(out.end(), {v.x(), v.y(), v.z()});
}

// The 4x4 matrix, row after row: exactly the pose (a replay sets it back bit for bit).
void push_pose(std::vector<double>& out, const Eigen::Isometry3d& pose) {
  const Eigen::Matrix4d& m = pose.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out.push_back(m(r, c));
  }
}

const Drill& as_drill(const Object& o) { return static_cast<const Drill&>(o); }
const InputDevice& as_device(const Object& o) { return static_cast<const InputDevice&>(o); }

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

  // A device has no pose of its own: its reading and the force sent back are its state.
  void add_step_log_columns(const Object& object, StepLogColumns& columns) const override {
    if (object.kind() != ObjectKind::kInputDevice) return;
    columns.drop_pose();
    columns.add("position", 3, [](const Object& o, std::vector<double>& out) {
      push(out, as_device(o).state().position);
    });
    columns.add("orientation", 4, [](const Object& o, std::vector<double>& out) {
      const Eigen::Quaterniond& q = as_device(o).state().orientation;
      out.insert(out.end(), {q.x(), q.y(), q.z(), q.w()});
    });
    columns.add("buttons", 1, [](const Object& o, std::vector<double>& out) {
      out.push_back(as_device(o).state().buttons);
    });
    columns.add("force", 3,
                [](const Object& o, std::vector<double>& out) { push(out, as_device(o).force()); });
  }

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

  void add_step_log_columns(const Object& object, StepLogColumns& columns) const override {
    if (object.kind() != ObjectKind::kDrill) return;
    columns.add("goal", 16, [](const Object& o, std::vector<double>& out) {
      push_pose(out, as_drill(o).goal());
    });
    columns.add("force", 3,
                [](const Object& o, std::vector<double>& out) { push(out, as_drill(o).force()); });
    columns.add("total_force", 3, [](const Object& o, std::vector<double>& out) {
      push(out, as_drill(o).total_force());
    });
    columns.add("fixture_force", 3, [](const Object& o, std::vector<double>& out) {
      push(out, as_drill(o).fixture_force());
    });
    columns.add("on", 1, [](const Object& o, std::vector<double>& out) {
      out.push_back(as_drill(o).on() ? 1.0 : 0.0);
    });
    columns.add("burr", 1, [](const Object& o, std::vector<double>& out) {
      out.push_back(as_drill(o).burr());
    });
    columns.add("leading", 1, [](const Object& o, std::vector<double>& out) {
      out.push_back(as_drill(o).leading_cursor());
    });
    // Metres from the burr's surface to each critical structure (critical_labels() order), so
    // that a recording replays the proximity warnings.
    const std::size_t critical = as_drill(object).critical_labels().size();
    if (critical > 0) {
      columns.add(
          "critical_distance", static_cast<int>(critical),
          [critical](const Object& o, std::vector<double>& out) {
            const auto& d = as_drill(o).critical_distances();
            for (std::size_t i = 0; i < critical; ++i) {
              out.push_back(i < d.size() ? d[i].second : std::numeric_limits<double>::infinity());
            }
          });
    }
  }

  void run(StepStage, const StepContext& context) override {
    for (Drill* d : drills_) {
      d->set_realtime(context.realtime);
      d->tick(context.dt, context.step);
    }
  }

 private:
  std::vector<Drill*> drills_;
};

}  // namespace

std::unique_ptr<System> make_device_system() { return std::make_unique<DeviceSystem>(); }

std::unique_ptr<System> make_drill_system() { return std::make_unique<DrillSystem>(); }

}  // namespace ambfplus::haptics
