#include "ambfplus/scene/step_log.h"

#include <algorithm>

#include <Eigen/Geometry>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/input_device.h"

namespace ambfplus {
namespace {

// The 4x4 matrix, row after row: exactly the pose (a replay sets it back bit for bit).
void push_pose(std::vector<double>& out, const Eigen::Isometry3d& pose) {
  const Eigen::Matrix4d& m = pose.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out.push_back(m(r, c));
  }
}

void push(std::vector<double>& out, const Eigen::Vector3d& v) {
  out.insert(out.end(), {v.x(), v.y(), v.z()});
}

}  // namespace

StepLog::StepLog(std::vector<const Object*> objects) : objects_(std::move(objects)) {
  for (const Object* o : objects_) {
    const std::string& n = o->name();
    // An input device has no pose of its own: its reading is its state.
    if (o->kind() != ObjectKind::kInputDevice) columns_.push_back({n + ".pose", 16, {}});
    if (o->kind() == ObjectKind::kDrill) {
      for (const auto& [field, width] : std::vector<std::pair<const char*, int>>{{"goal", 16},
                                                                                 {"force", 3},
                                                                                 {"total_force", 3},
                                                                                 {"on", 1},
                                                                                 {"burr", 1},
                                                                                 {"leading", 1}}) {
        columns_.push_back({n + "." + field, width, {}});
      }
    } else if (o->kind() == ObjectKind::kInputDevice) {
      for (const auto& [field, width] : std::vector<std::pair<const char*, int>>{
               {"position", 3}, {"orientation", 4}, {"buttons", 1}, {"force", 3}}) {
        columns_.push_back({n + "." + field, width, {}});
      }
    }
  }
}

void StepLog::record(std::int64_t step, double time) {
  steps_.push_back(step);
  times_.push_back(time);
  std::size_t c = 0;
  for (const Object* o : objects_) {
    if (o->kind() != ObjectKind::kInputDevice) push_pose(columns_[c++].values, o->pose());
    if (const auto* drill = dynamic_cast<const Drill*>(o)) {
      push_pose(columns_[c++].values, drill->goal());
      push(columns_[c++].values, drill->force());
      push(columns_[c++].values, drill->total_force());
      columns_[c++].values.push_back(drill->on() ? 1.0 : 0.0);
      columns_[c++].values.push_back(drill->burr());
      columns_[c++].values.push_back(drill->leading_cursor());
    } else if (const auto* device = dynamic_cast<const InputDevice*>(o)) {
      const DeviceState& s = device->state();
      push(columns_[c++].values, s.position);
      const Eigen::Quaterniond& q = s.orientation;
      columns_[c++].values.insert(columns_[c - 1].values.end(), {q.x(), q.y(), q.z(), q.w()});
      columns_[c++].values.push_back(s.buttons);
      push(columns_[c++].values, device->force());
    }
  }
}

StepLog StepLog::take() {
  StepLog out;
  out.objects_ = objects_;
  out.steps_.swap(steps_);
  out.times_.swap(times_);
  out.columns_.swap(columns_);
  out.dropped_ = dropped_;
  for (const Column& c : out.columns_) columns_.push_back({c.name, c.width, {}});
  return out;
}

std::size_t StepLog::values() const {
  std::size_t n = 0;
  for (const Column& c : columns_) n += c.values.size();
  return n;
}

void StepLog::drop_oldest(std::int64_t n) {
  n = std::clamp<std::int64_t>(n, 0, rows());
  steps_.erase(steps_.begin(), steps_.begin() + n);
  times_.erase(times_.begin(), times_.begin() + n);
  for (Column& c : columns_) c.values.erase(c.values.begin(), c.values.begin() + n * c.width);
  dropped_ += n;
}

bool StepLog::logs(const Object& object) const {
  return std::find(objects_.begin(), objects_.end(), &object) != objects_.end();
}

}  // namespace ambfplus
