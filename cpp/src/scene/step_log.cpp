#include "ambfplus/scene/step_log.h"

#include <algorithm>

#include <Eigen/Geometry>

#include "ambfplus/errors.h"
#include "ambfplus/scene/object.h"

namespace ambfplus {
namespace {

// The 4x4 matrix, row after row: exactly the pose (a replay sets it back bit for bit).
void push_pose(std::vector<double>& out, const Eigen::Isometry3d& pose) {
  const Eigen::Matrix4d& m = pose.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out.push_back(m(r, c));
  }
}

}  // namespace

void StepLogColumns::add(std::string name, int width, Recorder record) {
  if (width < 1 || !record) {
    throw ArgumentError("step log column '" + object_->key() + "." + name +
                        "' needs a width of at least 1 and a recorder");
  }
  fields_.push_back({std::move(name), width, std::move(record)});
}

StepLog::StepLog(std::vector<StepLogColumns> objects) : objects_(std::move(objects)) {
  // Columns are named by the objects' keys ("psm1/link.pose" under a namespace): unique.
  for (const StepLogColumns& o : objects_) {
    const std::string n = o.object().key();
    if (o.pose()) columns_.push_back({n + ".pose", 16, {}});
    for (const StepLogColumns::Field& f : o.fields())
      columns_.push_back({n + "." + f.name, f.width, {}});
  }
}

void StepLog::record(std::int64_t step, double time) {
  steps_.push_back(step);
  times_.push_back(time);
  std::size_t c = 0;
  for (const StepLogColumns& o : objects_) {
    if (o.pose()) push_pose(columns_[c++].values, o.object().pose());
    for (const StepLogColumns::Field& f : o.fields()) f.record(o.object(), columns_[c++].values);
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
  return std::any_of(objects_.begin(), objects_.end(),
                     [&](const StepLogColumns& o) { return &o.object() == &object; });
}

}  // namespace ambfplus
