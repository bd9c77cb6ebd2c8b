#include "ambfplus/volume/structure_distances.h"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "ambfplus/errors.h"
#include "volume/grid_access.h"

namespace ambfplus {
namespace {

// A rebuild's thread runs at normal priority, whatever the thread that started it (a real-time
// loop's SCHED_FIFO thread passes its policy on to threads it creates).
void run_at_normal_priority() {
  sched_param p{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
}

// Whether box a lies inside box b.
bool within(const VoxelBox& a, const VoxelBox& b) {
  for (int axis = 0; axis < 3; ++axis) {
    if (a.lo[axis] < b.lo[axis] || a.hi[axis] > b.hi[axis]) return false;
  }
  return true;
}

bool overlap(const VoxelBox& a, const VoxelBox& b) {
  for (int axis = 0; axis < 3; ++axis) {
    if (a.hi[axis] <= b.lo[axis] || b.hi[axis] <= a.lo[axis]) return false;
  }
  return !a.empty() && !b.empty();
}

}  // namespace

class StructureDistances::Worker {
 public:
  Worker() : pid_(getpid()), thread_([this] { run(); }) {}
  /// In a forked child the thread is the parent's and does not run here: the worker must then
  /// be neither joined nor destroyed (its condition variable counts the parent's waiter).
  bool forked() const { return getpid() != pid_; }
  ~Worker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();  // after the jobs handed over so far
  }
  template <class F>
  auto submit(F&& job) -> std::future<decltype(job())> {
    using R = decltype(job());
    auto task = std::make_shared<std::packaged_task<R()>>(std::forward<F>(job));
    std::future<R> done = task->get_future();
    if (forked()) {  // a forked child: a thread of its own for the job
      std::thread([task] {
        run_at_normal_priority();
        (*task)();
      }).detach();
      return done;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_.emplace_back([task] { (*task)(); });
    }
    wake_.notify_one();
    return done;
  }

 private:
  void run() {
    run_at_normal_priority();
    for (;;) {
      std::function<void()> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
        if (jobs_.empty()) return;  // stopping, and nothing left
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      job();
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stop_ = false;
  pid_t pid_;
  std::thread thread_;
};

StructureDistances::StructureDistances(const VolumeData& data)
    : data_(data), worker_(std::make_unique<Worker>()) {}

StructureDistances::~StructureDistances() {
  if (worker_->forked()) {
    worker_.release();  // NOLINT: the parent's thread and state, left alone in a forked child
    return;
  }
  worker_.reset();  // every job handed over has run
}

StructureDistances::Entry* StructureDistances::find(int label) {
  for (Entry& e : entries_) {
    if (e.label == label) return &e;
  }
  return nullptr;
}

const StructureDistances::Entry* StructureDistances::find(int label) const {
  for (const Entry& e : entries_) {
    if (e.label == label) return &e;
  }
  return nullptr;
}

std::unique_ptr<VolumeData> StructureDistances::copy(int label, const VoxelBox& box) const {
  const std::array<int, 3> shape{box.hi[0] - box.lo[0], box.hi[1] - box.lo[1],
                                 box.hi[2] - box.lo[2]};
  const Eigen::Vector3d size =
      data_.voxel_size().cwiseProduct(Eigen::Vector3d(shape[0], shape[1], shape[2]));
  auto snapshot = std::make_unique<VolumeData>(
      shape, size, LabelType::kUInt8,
      LabelTable({Label{1, "structure", {255, 255, 255}, true, true}}));
  // Row by row over the raw grid (the compiler vectorises the compare): this runs on the
  // haptic thread, once per rebuild.
  auto* out = static_cast<std::uint8_t*>(snapshot->label_data());
  const auto& n = data_.shape();
  const int width = shape[0];
  visit_labels(data_.label_type(), data_.label_data(), [&](const auto* grid) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(grid)>>;
    const T wanted = static_cast<T>(label);
    for (int k = box.lo[2]; k < box.hi[2]; ++k) {
      for (int j = box.lo[1]; j < box.hi[1]; ++j) {
        const std::size_t start =
            box.lo[0] + static_cast<std::size_t>(n[0]) * (j + static_cast<std::size_t>(n[1]) * k);
        const T* row = grid + start;
        if (label > 0) {
          for (int i = 0; i < width; ++i) out[i] = row[i] == wanted;
        } else if (label < kPlanTarget) {
          const std::vector<bool>& in = sets_[static_cast<std::size_t>(kPlanTarget - 1 - label)];
          for (int i = 0; i < width; ++i) out[i] = in[row[i]];
        } else if (label == kOutsidePlan) {
          const std::uint8_t* in_plan = plan_->data() + start;
          for (int i = 0; i < width; ++i) out[i] = row[i] != 0 && in_plan[i] == 0;
        } else {
          const std::uint8_t* in_plan = plan_->data() + start;
          for (int i = 0; i < width; ++i) out[i] = row[i] != 0 && in_plan[i] != 0;
        }
        out += width;
      }
    }
    return 0;
  });
  return snapshot;
}

std::shared_ptr<const StructureDistances::Field> StructureDistances::finish(
    std::unique_ptr<VolumeData> snapshot, std::unique_ptr<DistanceField> field, VoxelBox box,
    Eigen::Vector3d offset) {
  auto f = std::make_shared<Field>();
  // A field brought up to date keeps the box of its first build (cuts only shrink the
  // structure): still around every voxel, so the distance beyond the band stays a lower bound.
  const VoxelBox& b = field->bounds();
  if (!b.empty() && field->structure_voxels() > 0) {
    const Eigen::Vector3d a = snapshot->voxel_center(b.lo[0], b.lo[1], b.lo[2]) + offset;
    const Eigen::Vector3d c =
        snapshot->voxel_center(b.hi[0] - 1, b.hi[1] - 1, b.hi[2] - 1) + offset;
    f->lo = a.cwiseMin(c);
    f->hi = a.cwiseMax(c);
    for (int axis = 0; axis < 3; ++axis) {
      f->bounds.lo[axis] = b.lo[axis] + box.lo[axis];
      f->bounds.hi[axis] = b.hi[axis] + box.lo[axis];
    }
  }
  f->field = std::move(field);
  f->snapshot = std::move(snapshot);
  f->box = box;
  f->offset = offset;
  return f;
}

namespace {

// Writes `patch` (the structure's voxels over `box`, snapshot coordinates) into `snapshot`.
void write_patch(VolumeData& snapshot, const VolumeData& patch, const VoxelBox& box) {
  const auto& n = snapshot.shape();
  const auto* in = static_cast<const std::uint8_t*>(patch.label_data());
  auto* out = static_cast<std::uint8_t*>(snapshot.label_data());
  const int width = box.hi[0] - box.lo[0];
  for (int k = box.lo[2]; k < box.hi[2]; ++k) {
    for (int j = box.lo[1]; j < box.hi[1]; ++j) {
      std::copy_n(in, width,
                  out + box.lo[0] +
                      static_cast<std::size_t>(n[0]) *
                          (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * k));
      in += width;
    }
  }
  snapshot.mark_dirty(box);
}

}  // namespace

std::future<std::shared_ptr<const StructureDistances::Field>> StructureDistances::follow(Entry& e) {
  std::shared_ptr<const Field> base = e.current;
  // The spare (the field current replaced) is brought up to date in place when it has the
  // same box: over the cut and over where it lags behind current.
  std::shared_ptr<const Field> spare;
  VoxelBox cut = e.cut;
  if (e.spare != nullptr && e.spare->box == base->box) {
    spare = std::move(e.spare);
    cut = cut.united(e.spare_lag);
  } else if (e.spare != nullptr) {
    worker_->submit([old = std::move(e.spare)]() mutable { old.reset(); });
  }
  e.spare = nullptr;
  e.spare_lag = VoxelBox{};
  e.next_patch = cut;
  // The structure's voxels over the cut, as they are now, copied here (the other thread never
  // reads the volume), in the snapshot's coordinates.
  std::unique_ptr<VolumeData> patch = copy(e.label, cut);
  for (int a = 0; a < 3; ++a) {
    cut.lo[a] -= base->box.lo[a];
    cut.hi[a] -= base->box.lo[a];
  }
  if (spare != nullptr) {
    return worker_->submit([spare = std::move(spare), patch = std::move(patch),
                            cut]() mutable -> std::shared_ptr<const Field> {
      // Nothing else holds the spare: the entry gave it up, and only `current` is read.
      const std::shared_ptr<Field> f = std::const_pointer_cast<Field>(spare);
      write_patch(*f->snapshot, *patch, cut);
      f->field->update();
      return finish(std::move(f->snapshot), std::move(f->field), f->box, f->offset);
    });
  }
  return worker_->submit([base = std::move(base), patch = std::move(patch),
                          cut]() mutable -> std::shared_ptr<const Field> {
    const VolumeData& from = *base->snapshot;
    auto snapshot = std::make_unique<VolumeData>(from.shape(), from.dimensions(), LabelType::kUInt8,
                                                 from.label_table());
    const std::size_t count = static_cast<std::size_t>(from.voxel_count());
    std::copy_n(static_cast<const std::uint8_t*>(from.label_data()), count,
                static_cast<std::uint8_t*>(snapshot->label_data()));
    auto field = std::make_unique<DistanceField>(*base->field, *snapshot);
    write_patch(*snapshot, *patch, cut);
    field->update();
    return finish(std::move(snapshot), std::move(field), base->box, base->offset);
  });
}

std::future<std::shared_ptr<const StructureDistances::Field>> StructureDistances::rebuild(
    const Entry& e, const VoxelBox& bounds) const {
  // The copy is made here, on the caller's thread: the other thread never reads the volume.
  const Eigen::Vector3d s = data_.voxel_size();
  std::array<int, 3> reach;
  for (int a = 0; a < 3; ++a) reach[a] = static_cast<int>(std::ceil(e.band / s[a])) + 2;
  VoxelBox box = bounds;
  for (int a = 0; a < 3; ++a) {
    box.lo[a] -= reach[a];
    box.hi[a] += reach[a];
  }
  box = box.clipped(data_.shape());
  if (bounds.empty()) box = VoxelBox{{0, 0, 0}, {1, 1, 1}};  // nothing left: a field of nothing
  std::unique_ptr<VolumeData> snapshot = copy(e.label, box);
  if (bounds.empty()) static_cast<std::uint8_t*>(snapshot->label_data())[0] = 0;
  const Eigen::Vector3d offset =
      data_.voxel_center(box.lo[0], box.lo[1], box.lo[2]) - snapshot->voxel_center(0, 0, 0);
  const double band = e.band;
  return worker_->submit([snapshot = std::move(snapshot), box, offset,
                          band]() mutable -> std::shared_ptr<const Field> {
    auto field = std::make_unique<DistanceField>(*snapshot, std::vector<std::uint16_t>{1}, band);
    return finish(std::move(snapshot), std::move(field), box, offset);
  });
}

void StructureDistances::set_plan(std::shared_ptr<const std::vector<std::uint8_t>> mask) {
  plan_ = std::move(mask);
  for (int label : {kOutsidePlan, kPlanTarget}) {
    if (Entry* e = find(label)) {
      const double band = e->band;
      e->band = 0.0;  // rebuilt now, whatever its band
      track(label, band);
    }
  }
}

int StructureDistances::track_labels(const std::vector<std::uint16_t>& labels, double band) {
  std::vector<std::uint16_t> sorted = labels;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  if (sorted.empty() || sorted.front() == 0) {
    throw ArgumentError("StructureDistances: a structure needs labels, none of them 0");
  }
  std::size_t n = 0;
  while (n < set_labels_.size() && set_labels_[n] != sorted) ++n;
  if (n == set_labels_.size()) {
    std::vector<bool> in(65536, false);
    for (std::uint16_t id : sorted) in[id] = true;
    sets_.push_back(std::move(in));
    set_labels_.push_back(sorted);
  }
  const int key = kPlanTarget - 1 - static_cast<int>(n);
  track(key, band);
  return key;
}

void StructureDistances::track(int label, double band) {
  notice_edits();
  Entry* e = find(label);
  if (e != nullptr && e->band >= band) return;
  if (e == nullptr) {
    entries_.emplace_back();
    e = &entries_.back();
    e->label = label;
    e->band = band;
  }
  if (e->next.valid()) e->next.wait();
  e->band = band;
  // The structure's bounds, from one pass over the volume.
  const auto& n = data_.shape();
  VoxelBox bounds{{n[0], n[1], n[2]}, {0, 0, 0}};
  bool any = false;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        if (!member(label, data_.label(i, j, k), i, j, k)) continue;
        any = true;
        const int c[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          bounds.lo[a] = std::min(bounds.lo[a], c[a]);
          bounds.hi[a] = std::max(bounds.hi[a], c[a] + 1);
        }
      }
    }
  }
  e->spare = nullptr;
  e->spare_lag = VoxelBox{};
  e->next_patch = VoxelBox{};
  e->current = rebuild(*e, any ? bounds : VoxelBox{}).get();
  e->next = {};
  e->changed = false;
  e->grown = VoxelBox{};
  e->cut = VoxelBox{};
  e->whole = false;
  seen_ = data_.revision();
}

void StructureDistances::notice_edits() {
  if (seen_ < 0 || seen_ == data_.revision()) {
    seen_ = data_.revision();
    return;
  }
  std::vector<VoxelBox> boxes;
  const bool any = data_.dirty_boxes_since(seen_, &boxes);
  seen_ = data_.revision();
  if (!any) return;
  for (Entry& e : entries_) {
    for (const VoxelBox& dirty : boxes) {
      const VoxelBox box = dirty.clipped(data_.shape());
      if (overlap(box, e.current->box)) {
        // Within the structure's neighbourhood: followed locally when the edit stayed inside
        // it, else built anew (the structure may have been painted beyond it).
        e.changed = true;
        if (within(box, e.current->box)) {
          e.cut = e.cut.united(box);
        } else {
          e.whole = true;
          e.grown = e.grown.united(box);
        }
        continue;
      }
      // Farther away an edit matters only if it painted the structure there.
      bool painted = false;
      for (int k = box.lo[2]; k < box.hi[2] && !painted; ++k) {
        for (int j = box.lo[1]; j < box.hi[1] && !painted; ++j) {
          for (int i = box.lo[0]; i < box.hi[0]; ++i) {
            if (member(e.label, data_.label(i, j, k), i, j, k)) {
              painted = true;
              break;
            }
          }
        }
      }
      if (painted) {
        e.changed = true;
        e.grown = e.grown.united(box);
      }
    }
  }
}

void StructureDistances::removed(std::int64_t before, const std::vector<std::array<int, 3>>& voxels,
                                 const std::vector<std::uint16_t>& labels) {
  for (Entry& e : entries_) {
    for (std::size_t n = 0; n < voxels.size(); ++n) {
      const std::array<int, 3>& v = voxels[n];
      if (!member(e.label, labels[n], v[0], v[1], v[2])) continue;
      e.changed = true;
      // A removed voxel of the structure lies inside its bounds, so inside the snapshot's box.
      e.cut = e.cut.united(VoxelBox{v, {v[0] + 1, v[1] + 1, v[2] + 1}});
    }
  }
  if (before < 0 || seen_ == before) seen_ = data_.revision();  // else notice_edits() scans
}

void StructureDistances::start(Entry& e) {
  const Field& f = *e.current;
  // Local while the structure stays inside the snapshot's box and the cut is not most of it.
  const bool local = !e.whole && e.grown.empty() && !f.bounds.empty() && !e.cut.empty() &&
                     within(e.cut, f.box) && 4 * e.cut.count() < f.box.count();
  if (!local) {
    e.next_patch = VoxelBox{};
    if (e.spare != nullptr) worker_->submit([old = std::move(e.spare)]() mutable { old.reset(); });
    e.spare = nullptr;
    e.spare_lag = VoxelBox{};
  }
  e.next = local ? follow(e) : rebuild(e, f.bounds.united(e.grown).united(e.cut));
  local_updates_ += local ? 1 : 0;
  e.due = tick_ + kFollowTicks;
  e.changed = false;
  e.grown = VoxelBox{};
  e.cut = VoxelBox{};
  e.whole = false;
}

void StructureDistances::tick(bool wait) {
  ++tick_;
  notice_edits();
  taken_.clear();
  for (Entry& e : entries_) {
    const bool ready = e.next.valid() && (wait || e.next.wait_for(std::chrono::seconds(0)) ==
                                                      std::future_status::ready);
    if (ready && tick_ >= e.due) take(e);
    if (!e.next.valid() && e.changed) start(e);
  }
}

void StructureDistances::tick_taking(const std::vector<int>& take_keys) {
  ++tick_;
  notice_edits();
  taken_.clear();
  for (Entry& e : entries_) {
    if (std::find(take_keys.begin(), take_keys.end(), e.label) != take_keys.end()) {
      if (!e.next.valid()) {
        throw StateError("distance fields: the schedule takes structure " +
                         std::to_string(e.label) + "'s field at tick " + std::to_string(tick_) +
                         ", but no update of it is under way (a schedule of another session)");
      }
      take(e);
    }
    if (!e.next.valid() && e.changed) start(e);
  }
}

void StructureDistances::take(Entry& e) {
  std::shared_ptr<const Field> old = std::move(e.current);
  // A successor not built yet is waited for (scripted stepping on a machine slower than
  // kFollowTicks, or a replayed schedule).
  if (e.next.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    const auto began = std::chrono::steady_clock::now();
    e.next.wait();
    ++waits_;
    wait_seconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  }
  e.current = e.next.get();
  ++rebuilds_;
  if (!e.next_patch.empty() && e.spare == nullptr) {
    e.spare = std::move(old);  // behind current over the patch just applied
    e.spare_lag = e.next_patch;
  } else {
    worker_->submit([old = std::move(old)]() mutable { old.reset(); });
  }
  e.next_patch = VoxelBox{};
  taken_.push_back(e.label);
}

double StructureDistances::distance(int label, const Eigen::Vector3d& p,
                                    Eigen::Vector3d* gradient) const {
  const Field& f = *find(label)->current;
  if (f.bounds.empty()) {
    if (gradient != nullptr) gradient->setZero();
    return std::numeric_limits<double>::infinity();
  }
  const double band = f.field->band();
  const Eigen::Vector3d gap = (f.lo - p).cwiseMax(p - f.hi).cwiseMax(0.0);
  // Two voxel diagonals beyond the band from the structure's box, every corner the sample
  // would read holds the band: the answer is the same without reading them.
  const double far = band + 2 * data_.voxel_size().norm();
  if (gap.squaredNorm() >= far * far) {
    if (gradient != nullptr) gradient->setZero();
    return gap.norm();
  }
  const DistanceSample s = f.field->sample(p - f.offset);
  if (s.distance < band) {
    if (gradient != nullptr) *gradient = s.gradient;
    return s.distance;
  }
  if (gradient != nullptr) gradient->setZero();
  return std::max(band, gap.norm());
}

}  // namespace ambfplus
