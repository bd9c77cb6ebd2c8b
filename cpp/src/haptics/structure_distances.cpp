#include "haptics/structure_distances.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ambfplus {

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

void StructureDistances::refresh_box(Entry& e) const {
  const VoxelBox& b = e.field->bounds();
  if (b.empty()) return;
  const Eigen::Vector3d a = data_.voxel_center(b.lo[0], b.lo[1], b.lo[2]);
  const Eigen::Vector3d c = data_.voxel_center(b.hi[0] - 1, b.hi[1] - 1, b.hi[2] - 1);
  e.lo = a.cwiseMin(c);
  e.hi = a.cwiseMax(c);
}

void StructureDistances::track(std::uint16_t label, double band) {
  Entry* e = find(label);
  if (e != nullptr && e->field->band() >= band) return;
  auto field = std::make_unique<DistanceField>(data_, std::vector<std::uint16_t>{label}, band);
  if (e == nullptr) {
    entries_.push_back(Entry{label, nullptr, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
    e = &entries_.back();
  }
  e->field = std::move(field);
  refresh_box(*e);
}

void StructureDistances::removed(std::int64_t before, const std::vector<std::uint16_t>& labels) {
  for (Entry& e : entries_) {
    if (e.field->revision() != before) continue;  // behind already: sync() scans
    if (std::find(labels.begin(), labels.end(), e.label) == labels.end()) {
      e.field->skip_to(data_.revision());
    }
  }
}

void StructureDistances::sync() {
  for (Entry& e : entries_) {
    if (e.field->revision() == data_.revision()) continue;
    const VoxelBox before = e.field->bounds();
    e.field->update();
    if (!(e.field->bounds() == before)) refresh_box(e);
  }
}

double StructureDistances::distance(std::uint16_t label, const Eigen::Vector3d& p,
                                    Eigen::Vector3d* gradient) const {
  const Entry& e = *find(label);
  if (e.field->structure_voxels() == 0) {
    if (gradient != nullptr) gradient->setZero();
    return std::numeric_limits<double>::infinity();
  }
  const DistanceSample s = e.field->sample(p);
  const double band = e.field->band();
  if (s.distance < band) {
    if (gradient != nullptr) *gradient = s.gradient;
    return s.distance;
  }
  if (gradient != nullptr) gradient->setZero();
  const Eigen::Vector3d gap = (e.lo - p).cwiseMax(p - e.hi).cwiseMax(0.0);
  return std::max(band, gap.norm());
}

double StructureDistances::band(std::uint16_t label) const { return find(label)->field->band(); }

}  // namespace ambfplus
