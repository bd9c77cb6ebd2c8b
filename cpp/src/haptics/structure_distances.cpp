#include "haptics/structure_distances.h"

#include <chrono>

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "volume/grid_access.h"

namespace ambfplus {
namespace {

// A rebuild's thread runs at normal priority, whatever the thread that started it (a real-time
// loop's SCHED_FIFO thread passes its policy on to threads it creates).
void run_at_normal_priority() {
  sched_param p{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
}

bool overlap(const VoxelBox& a, const VoxelBox& b) {
  for (int axis = 0; axis < 3; ++axis) {
    if (a.hi[axis] <= b.lo[axis] || b.hi[axis] <= a.lo[axis]) return false;
  }
  return !a.empty() && !b.empty();
}

}  // namespace

StructureDistances::~StructureDistances() {
  for (Entry& e : entries_) {
    if (e.next.valid()) e.next.wait();
  }
  if (retiring_.valid()) retiring_.wait();
}

StructureDistances::Entry* StructureDistances::find(std::uint16_t label) {
  for (Entry& e : entries_) {
    if (e.label == label) return &e;
  }
  return nullptr;
}

const StructureDistances::Entry* StructureDistances::find(std::uint16_t label) const {
  for (const Entry& e : entries_) {
    if (e.label == label) return &e;
  }
  return nullptr;
}

std::unique_ptr<VolumeData> StructureDistances::copy(std::uint16_t label,
                                                     const VoxelBox& box) const {
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
        if (label != 0) {
          for (int i = 0; i < width; ++i) out[i] = row[i] == wanted;
        } else {
          const std::uint8_t* in_plan = plan_->data() + start;
          for (int i = 0; i < width; ++i) out[i] = row[i] != 0 && in_plan[i] == 0;
        }
        out += width;
      }
    }
    return 0;
  });
  return snapshot;
}

std::shared_ptr<const StructureDistances::Field> StructureDistances::finish(
    std::unique_ptr<VolumeData> snapshot, VoxelBox box, Eigen::Vector3d offset, double band) {
  auto f = std::make_shared<Field>();
  f->field = std::make_unique<DistanceField>(*snapshot, std::vector<std::uint16_t>{1}, band);
  const VoxelBox& b = f->field->bounds();
  if (!b.empty()) {
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
  f->snapshot = std::move(snapshot);
  f->box = box;
  f->offset = offset;
  return f;
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
  return std::async(std::launch::async,
                    [snapshot = std::move(snapshot), box, offset, band]() mutable {
                      run_at_normal_priority();
                      return finish(std::move(snapshot), box, offset, band);
                    });
}

void StructureDistances::set_plan(std::shared_ptr<const std::vector<std::uint8_t>> mask) {
  plan_ = std::move(mask);
  if (Entry* e = find(0)) {
    const double band = e->band;
    e->band = 0.0;  // rebuilt now, whatever its band
    track(0, band);
  }
}

void StructureDistances::track(std::uint16_t label, double band) {
  notice_edits();
  Entry* e = find(label);
  if (e != nullptr && e->band >= band) return;
  if (e == nullptr) {
    entries_.push_back(Entry{label, band, nullptr, {}, 0, false, VoxelBox{}});
    e = &entries_.back();
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
  e->current = rebuild(*e, any ? bounds : VoxelBox{}).get();
  e->next = {};
  e->changed = false;
  e->grown = VoxelBox{};
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
        e.changed = true;  // within the structure's neighbourhood: rebuild, to be sure
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
    for (std::size_t n = 0; n < voxels.size() && !e.changed; ++n) {
      const std::array<int, 3>& v = voxels[n];
      e.changed = member(e.label, labels[n], v[0], v[1], v[2]);
    }
  }
  if (seen_ == before) seen_ = data_.revision();  // else notice_edits() scans them all
}

void StructureDistances::tick(bool wait) {
  ++tick_;
  notice_edits();
  for (Entry& e : entries_) {
    const bool ready = e.next.valid() && (wait || e.next.wait_for(std::chrono::seconds(0)) ==
                                                      std::future_status::ready);
    if (ready && tick_ >= e.due) {
      std::shared_ptr<const Field> old = std::move(e.current);
      e.current = e.next.get();  // waits only if the machine is slower than kFollowTicks
      ++rebuilds_;
      if (retiring_.valid()) retiring_.wait();
      retiring_ = std::async(std::launch::async, [old = std::move(old)]() mutable {
        run_at_normal_priority();
        old.reset();
      });
    }
    if (!e.next.valid() && e.changed) {
      e.next = rebuild(e, e.current->bounds.united(e.grown));
      e.due = tick_ + kFollowTicks;
      e.changed = false;
      e.grown = VoxelBox{};
    }
  }
}

double StructureDistances::distance(std::uint16_t label, const Eigen::Vector3d& p,
                                    Eigen::Vector3d* gradient) const {
  const Field& f = *find(label)->current;
  if (f.bounds.empty()) {
    if (gradient != nullptr) gradient->setZero();
    return std::numeric_limits<double>::infinity();
  }
  const DistanceSample s = f.field->sample(p - f.offset);
  const double band = f.field->band();
  if (s.distance < band) {
    if (gradient != nullptr) *gradient = s.gradient;
    return s.distance;
  }
  if (gradient != nullptr) gradient->setZero();
  const Eigen::Vector3d gap = (f.lo - p).cwiseMax(p - f.hi).cwiseMax(0.0);
  return std::max(band, gap.norm());
}

}  // namespace ambfplus
