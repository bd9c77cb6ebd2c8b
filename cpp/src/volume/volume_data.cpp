#include "ambfplus/volume/volume_data.h"
#include "ambfplus/errors.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "volume/grid_access.h"

namespace ambfplus {

// ---------------------------------------------------------------------------------------------
// VoxelBox

bool VoxelBox::empty() const { return hi[0] <= lo[0] || hi[1] <= lo[1] || hi[2] <= lo[2]; }

std::int64_t VoxelBox::count() const {
  if (empty()) return 0;
  return std::int64_t(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

VoxelBox VoxelBox::united(const VoxelBox& o) const {
  if (empty()) return o;
  if (o.empty()) return *this;
  VoxelBox b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = std::min(lo[a], o.lo[a]);
    b.hi[a] = std::max(hi[a], o.hi[a]);
  }
  return b;
}

VoxelBox VoxelBox::clipped(const std::array<int, 3>& shape) const {
  VoxelBox b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = std::clamp(lo[a], 0, shape[a]);
    b.hi[a] = std::clamp(hi[a], 0, shape[a]);
  }
  return b;
}

VoxelBox VoxelBox::grown(int margin) const {
  VoxelBox b = *this;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] -= margin;
    b.hi[a] += margin;
  }
  return b;
}

// ---------------------------------------------------------------------------------------------
// VolumeData

namespace {

constexpr std::size_t kDirtyHistory = 4096;

std::size_t label_bytes(LabelType t) { return t == LabelType::kUInt8 ? 1 : 2; }

// Throws unless box is a box of the grid: lo <= hi on every axis (ArgumentError) and inside
// [0, shape] (OutOfRange). An empty box (lo == hi) is fine.
void check_box(const char* what, const VoxelBox& box, const std::array<int, 3>& shape) {
  auto text = [](const std::array<int, 3>& v) {
    return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) +
           ")";
  };
  for (int a = 0; a < 3; ++a) {
    if (box.lo[a] > box.hi[a]) {
      throw ArgumentError(std::string(what) + ": lo " + text(box.lo) + " is above hi " +
                          text(box.hi) + " on axis " + "ijk"[a] + " (expected lo <= hi)");
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (box.lo[a] < 0 || box.hi[a] > shape[a]) {
      throw OutOfRange(std::string(what) + ": box " + text(box.lo) + ".." + text(box.hi) +
                       " reaches outside the grid (0, 0, 0).." + text(shape));
    }
  }
}

void check_table_fits(const LabelTable& table, LabelType type) {
  if (type == LabelType::kUInt8 && table.max_id() > 255) {
    throw ArgumentError("label id " + std::to_string(table.max_id()) +
                        " does not fit a uint8 label grid (use uint16)");
  }
}

}  // namespace

VolumeData::VolumeData(const std::array<int, 3>& shape, const Eigen::Vector3d& dimensions,
                       LabelType type, LabelTable table)
    : shape_(shape), dimensions_(dimensions), label_type_(type), table_(std::move(table)) {
  for (int a = 0; a < 3; ++a) {
    if (shape_[a] <= 0 || shape_[a] > 8192) {
      throw ArgumentError("volume shape must be 1..8192 voxels per axis, got " +
                          std::to_string(shape_[0]) + "x" + std::to_string(shape_[1]) + "x" +
                          std::to_string(shape_[2]));
    }
  }
  set_dimensions(dimensions);
  check_table_fits(table_, label_type_);
  labels_.assign(static_cast<std::size_t>(voxel_count()) * label_bytes(label_type_), 0);
  original_ = labels_;
}

void check_volume_sizes(const Eigen::Vector3d& sizes, const std::string& what) {
  if (!(sizes.minCoeff() > 0.0) || !sizes.allFinite()) {
    std::ostringstream s;
    s << what << " must be three positive finite metres, got (" << sizes.x() << ", " << sizes.y()
      << ", " << sizes.z() << ")";
    throw ArgumentError(s.str());
  }
}

void VolumeData::set_dimensions(const Eigen::Vector3d& dimensions) {
  check_volume_sizes(dimensions, "volume dimensions");
  dimensions_ = dimensions;
}

std::int64_t VolumeData::voxel_count() const {
  return std::int64_t(shape_[0]) * shape_[1] * shape_[2];
}

Eigen::Vector3d VolumeData::voxel_size() const {
  return dimensions_.cwiseQuotient(Eigen::Vector3d(shape_[0], shape_[1], shape_[2]));
}

void VolumeData::set_label_table(LabelTable table) {
  check_table_fits(table, label_type_);
  table_ = std::move(table);
}

void VolumeData::name_labels_from(const LabelTable& named) {
  check_table_fits(named, label_type_);
  std::vector<std::uint16_t> to(static_cast<std::size_t>(table_.max_id()) + 1, 0);
  for (const Label& l : table_.labels()) to[l.id] = named.nearest(l.color);
  visit_labels(label_type_, labels_.data(), [&](auto* grid) {
    using T = std::remove_pointer_t<decltype(grid)>;
    const std::size_t n = static_cast<std::size_t>(voxel_count());
    for (std::size_t v = 0; v < n; ++v) {
      if (grid[v] != 0 && grid[v] < to.size()) grid[v] = static_cast<T>(to[grid[v]]);
    }
  });
  table_ = named;
  mark_dirty(VoxelBox{{0, 0, 0}, shape_});
  commit();
}

void VolumeData::mark_critical_structures() {
  std::vector<Label> labels = table_.labels();
  if (std::any_of(labels.begin(), labels.end(), [](const Label& l) { return l.critical; })) {
    return;
  }
  static const char* const kCritical[] = {"facial", "chorda", "nerve",     "ica",     "carotid",
                                          "sinus",  "dura",   "labyrinth", "cochlea", "iac"};
  bool named = false;
  for (Label& l : labels) {
    std::string lower = l.name;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const char* word : kCritical) {
      if (lower.find(word) != std::string::npos) l.critical = named = true;
    }
  }
  if (!named) {
    const std::vector<std::int64_t> counts = label_counts();
    if (counts.size() < 2) return;
    const auto commonest = static_cast<std::uint16_t>(
        std::max_element(counts.begin() + 1, counts.end()) - counts.begin());
    for (Label& l : labels) l.critical = l.id != commonest;
  }
  table_ = LabelTable(labels);
}

void VolumeData::mark_intensity_changed() {
  auto guarded = guard_lock();  // the world showing it renders under this lock
  ++intensity_revision_;
}

void VolumeData::set_intensity_type(IntensityType type) {
  auto guarded = guard_lock();
  ++intensity_revision_;
  intensity_type_ = type;
  const std::size_t bytes = type == IntensityType::kNone    ? 0
                            : type == IntensityType::kInt16 ? 2
                                                            : 4;
  intensity_.assign(static_cast<std::size_t>(voxel_count()) * bytes, 0);
  intensity_.shrink_to_fit();
}

Eigen::Vector3d VolumeData::voxel_center(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= shape_[0] || j >= shape_[1] || k >= shape_[2]) {
    throw OutOfRange("voxel_center: voxel (" + std::to_string(i) + ", " + std::to_string(j) + ", " +
                     std::to_string(k) + ") is outside the grid of " + std::to_string(shape_[0]) +
                     "x" + std::to_string(shape_[1]) + "x" + std::to_string(shape_[2]));
  }
  return from_voxel_units(Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
}

Eigen::Vector3d VolumeData::to_voxel_units(const Eigen::Vector3d& p) const {
  return (p + dimensions_ / 2).cwiseQuotient(voxel_size());
}

Eigen::Vector3d VolumeData::from_voxel_units(const Eigen::Vector3d& u) const {
  return u.cwiseProduct(voxel_size()) - dimensions_ / 2;
}

std::vector<std::int64_t> VolumeData::label_counts() const {
  std::vector<std::int64_t> counts(label_type_ == LabelType::kUInt8 ? 256 : 65536, 0);
  visit_labels(label_type_, labels_.data(), [&](auto* p) {
    const std::size_t n = static_cast<std::size_t>(voxel_count());
    for (std::size_t v = 0; v < n; ++v) ++counts[p[v]];
  });
  std::size_t last = counts.size();
  while (last > 1 && counts[last - 1] == 0) --last;
  counts.resize(last);
  return counts;
}

void VolumeData::record(VolumeEdit edit) {
  edit.revision = ++revision_;
  dirty_.emplace_back(edit.revision, edit.box);
  if (dirty_.size() > kDirtyHistory) {
    dirty_floor_ = dirty_.front().first;
    dirty_dropped_ = dirty_dropped_.united(dirty_.front().second);
    dirty_.pop_front();
  }
  // Readers bring the derived fields up to date; the editing thread (a haptic tick) only notes
  // what changed.
  mark_derived_stale(edit.box);
  log_edit(std::move(edit));
}

void VolumeData::log_edit(VolumeEdit edit) {
  edit_log_voxels_ += edit.voxels.size();
  edit_log_.push_back(std::move(edit));
  while (edit_log_.size() > kEditLogEdits ||
         (edit_log_voxels_ > kEditLogVoxels && edit_log_.size() > 1)) {
    edit_log_voxels_ -= edit_log_.front().voxels.size();
    edit_log_.pop_front();
    ++edit_log_dropped_;
  }
}

std::int64_t VolumeData::remove_sphere(const Eigen::Vector3d& center, double radius,
                                       bool only_removable) {
  auto guarded = guard_lock();  // the world showing it steps and renders under this lock
  if (!(radius >= 0.0) || !std::isfinite(radius) || !center.allFinite()) {
    throw ArgumentError(
        "remove_sphere needs a finite centre and a finite radius >= 0, got radius " +
        std::to_string(radius));
  }
  const Eigen::Vector3d s = voxel_size();
  const Eigen::Vector3d u = to_voxel_units(center);
  VoxelBox box;
  for (int a = 0; a < 3; ++a) {
    // Clamped before the conversion, so a far centre or a huge radius cannot overflow an int.
    const double lo = std::floor(u[a] - radius / s[a] - 0.5);
    const double hi = std::ceil(u[a] + radius / s[a] + 0.5) + 1;
    box.lo[a] = static_cast<int>(std::clamp(lo, 0.0, double(shape_[a])));
    box.hi[a] = static_cast<int>(std::clamp(hi, 0.0, double(shape_[a])));
  }
  std::vector<bool> keep(label_type_ == LabelType::kUInt8 ? 256 : 65536, false);
  if (only_removable) {
    for (const Label& l : table_.labels()) keep[l.id] = !l.removable;
  }
  VolumeEdit edit;
  edit.kind = "remove_sphere";
  const double r2 = radius * radius;
  VoxelBox changed;
  visit_labels(label_type_, labels_.data(), [&](auto* p) {
    for (int k = box.lo[2]; k < box.hi[2]; ++k) {
      for (int j = box.lo[1]; j < box.hi[1]; ++j) {
        for (int i = box.lo[0]; i < box.hi[0]; ++i) {
          auto& v = p[linear_index(i, j, k)];
          if (v == 0 || keep[v]) continue;
          if ((voxel_center(i, j, k) - center).squaredNorm() > r2) continue;
          edit.voxels.push_back({i, j, k});
          edit.old_labels.push_back(v);
          v = 0;
          changed = changed.united(VoxelBox{{i, j, k}, {i + 1, j + 1, k + 1}});
        }
      }
    }
  });
  const auto count = static_cast<std::int64_t>(edit.voxels.size());
  edit.changed = count;
  edit.box = changed;
  if (count > 0) record(std::move(edit));
  return count;
}

std::vector<std::uint16_t> VolumeData::remove_voxels(const std::vector<std::array<int, 3>>& voxels,
                                                     const std::string& kind) {
  auto guarded = guard_lock();  // the world showing it steps and renders under this lock
  std::vector<std::uint16_t> old(voxels.size(), 0);
  VolumeEdit edit;
  edit.kind = kind;
  visit_labels(label_type_, labels_.data(), [&](auto* p) {
    for (std::size_t n = 0; n < voxels.size(); ++n) {
      const auto& v = voxels[n];
      if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= shape_[0] || v[1] >= shape_[1] ||
          v[2] >= shape_[2]) {
        throw ArgumentError("remove_voxels: voxel outside the grid");
      }
      auto& l = p[linear_index(v[0], v[1], v[2])];
      old[n] = l;
      if (l == 0) continue;
      edit.voxels.push_back(v);
      edit.old_labels.push_back(l);
      l = 0;
      edit.box = edit.box.united(VoxelBox{v, {v[0] + 1, v[1] + 1, v[2] + 1}});
    }
  });
  edit.changed = static_cast<std::int64_t>(edit.voxels.size());
  if (edit.changed > 0) record(std::move(edit));
  return old;
}

std::int64_t VolumeData::set_region(const VoxelBox& region, std::uint16_t label) {
  auto guarded = guard_lock();  // the world showing it steps and renders under this lock
  if (label_type_ == LabelType::kUInt8 && label > 255) {
    throw ArgumentError("label " + std::to_string(label) + " does not fit a uint8 grid");
  }
  check_box("set_region", region, shape_);
  const VoxelBox box = region;
  std::int64_t changed = 0;
  visit_labels(label_type_, labels_.data(), [&](auto* p) {
    using T = std::remove_pointer_t<decltype(p)>;
    const T value = static_cast<T>(label);
    for (int k = box.lo[2]; k < box.hi[2]; ++k) {
      for (int j = box.lo[1]; j < box.hi[1]; ++j) {
        T* row = p + linear_index(0, j, k);
        for (int i = box.lo[0]; i < box.hi[0]; ++i) {
          changed += row[i] != value;
          row[i] = value;
        }
      }
    }
  });
  VolumeEdit edit;
  edit.kind = "set_region";
  edit.box = box;
  edit.changed = changed;
  if (!box.empty()) record(std::move(edit));
  return changed;
}

void VolumeData::mark_dirty(const VoxelBox& box) {
  auto guarded = guard_lock();  // the world showing it steps and renders under this lock
  check_box("mark_dirty", box, shape_);
  VolumeEdit edit;
  edit.kind = "mark_dirty";
  edit.box = box;
  if (!edit.box.empty()) record(std::move(edit));
}

void VolumeData::reset() {
  auto guarded = guard_lock();  // the world showing it steps and renders under this lock
  // Only the voxels that differ are rewritten, and only their box is marked.
  VoxelBox changed;
  std::int64_t count = 0;
  const std::size_t bytes = label_bytes(label_type_);
  for (int k = 0; k < shape_[2]; ++k) {
    for (int j = 0; j < shape_[1]; ++j) {
      const std::size_t row = linear_index(0, j, k) * bytes;
      const std::size_t len = static_cast<std::size_t>(shape_[0]) * bytes;
      if (std::memcmp(&labels_[row], &original_[row], len) == 0) continue;
      int first = shape_[0], last = -1;
      for (int i = 0; i < shape_[0]; ++i) {
        if (std::memcmp(&labels_[row + i * bytes], &original_[row + i * bytes], bytes) != 0) {
          first = std::min(first, i);
          last = i;
          ++count;
        }
      }
      std::memcpy(&labels_[row], &original_[row], len);
      changed = changed.united(VoxelBox{{first, j, k}, {last + 1, j + 1, k + 1}});
    }
  }
  VolumeEdit edit;
  edit.kind = "reset";
  edit.box = changed;
  edit.changed = count;
  record(std::move(edit));
}

void VolumeData::commit() {
  auto guarded = guard_lock();
  original_ = labels_;
}

bool VolumeData::dirty_since(std::int64_t since, VoxelBox* box) const {
  if (since >= revision_) return false;
  // Edits no longer listed lie within the union of those dropped.
  VoxelBox u = since < dirty_floor_ ? dirty_dropped_ : VoxelBox{};
  for (auto it = dirty_.rbegin(); it != dirty_.rend() && it->first > since; ++it) {
    u = u.united(it->second);
  }
  *box = u;
  return true;
}

bool VolumeData::dirty_boxes_since(std::int64_t since, std::vector<VoxelBox>* boxes,
                                   std::size_t max_boxes) const {
  boxes->clear();
  if (since >= revision_) return false;
  // Edits no longer listed lie within the union of those dropped (a drill's region, not the
  // grid, unless something edited it all).
  if (since < dirty_floor_ && !dirty_dropped_.empty()) boxes->push_back(dirty_dropped_);
  auto first = dirty_.end();
  while (first != dirty_.begin() && std::prev(first)->first > since) --first;
  for (auto it = first; it != dirty_.end(); ++it) {
    const VoxelBox& box = it->second;
    if (box.empty()) continue;
    // Consecutive edits of a tool overlap: one box for them costs few extra voxels.
    if (!boxes->empty()) {
      const VoxelBox merged = boxes->back().united(box);
      if (merged.count() <= 2 * (boxes->back().count() + box.count())) {
        boxes->back() = merged;
        continue;
      }
    }
    boxes->push_back(box);
  }
  if (boxes->size() > std::max<std::size_t>(max_boxes, 1)) {
    VoxelBox all;
    for (const VoxelBox& b : *boxes) all = all.united(b);
    boxes->assign(1, all);
  }
  return true;
}

std::deque<VolumeEdit> VolumeData::take_edit_log() {
  std::deque<VolumeEdit> out;
  out.swap(edit_log_);
  edit_log_voxels_ = 0;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Derived fields

namespace {

// Offset of voxel (i, j, k) in a box `frame` packed i fastest.
std::size_t packed_index(const VoxelBox& frame, int i, int j, int k) {
  const std::size_t w = static_cast<std::size_t>(frame.hi[0] - frame.lo[0]);
  const std::size_t h = static_cast<std::size_t>(frame.hi[1] - frame.lo[1]);
  return static_cast<std::size_t>(i - frame.lo[0]) +
         w * (static_cast<std::size_t>(j - frame.lo[1]) + h * (k - frame.lo[2]));
}

VoxelBox whole(const std::array<int, 3>& shape) { return VoxelBox{{0, 0, 0}, shape}; }

}  // namespace

VoxelBox bricks_reaching(const VoxelBox& voxels, const std::array<int, 3>& shape) {
  constexpr int B = VolumeData::kBrickSize;
  VoxelBox bricks;
  for (int a = 0; a < 3; ++a) {
    const int count = (shape[a] + B - 1) / B;
    bricks.lo[a] = std::max(0, (voxels.lo[a] - 1) / B);
    bricks.hi[a] = std::min(count, (voxels.hi[a] + 1) / B + 1);
  }
  return bricks;
}

VoxelBox brick_footprints(const VoxelBox& bricks, const std::array<int, 3>& shape) {
  constexpr int B = VolumeData::kBrickSize;
  VoxelBox voxels;
  for (int a = 0; a < 3; ++a) {
    voxels.lo[a] = bricks.lo[a] * B - 1;
    voxels.hi[a] = bricks.hi[a] * B + 1;
  }
  return voxels.clipped(shape);
}

void smooth_occupancy(const std::uint8_t* labels, const VoxelBox& labels_frame, int bytes,
                      const std::array<int, 3>& shape, const VoxelBox& box, std::uint8_t* out,
                      const VoxelBox& out_frame) {
  if (box.empty()) return;
  constexpr int R = VolumeData::kSmoothRadius;
  constexpr int kWeights[2 * R + 1] = {1, 4, 6, 4, 1};  // binomial: sums to 16 per axis
  const int w = box.hi[0] - box.lo[0], h = box.hi[1] - box.lo[1];
  // One row of occupancy (0 or 1) with R voxels either side, 0 beyond the grid.
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(w) + 2 * R);
  const int in_lo = std::max(0, box.lo[0] - R), in_hi = std::min(shape[0], box.hi[0] + R);
  auto read_row = [&](int j, int k) {
    std::fill(occupied.begin(), occupied.end(), 0);
    const std::size_t at = packed_index(labels_frame, in_lo, j, k);
    std::uint8_t* dst = occupied.data() + (in_lo - (box.lo[0] - R));
    if (bytes == 1) {
      const std::uint8_t* row = labels + at;
      for (int i = 0; i < in_hi - in_lo; ++i) dst[i] = row[i] != 0;
    } else {
      std::uint16_t value = 0;
      for (int i = 0; i < in_hi - in_lo; ++i) {
        std::memcpy(&value, labels + (at + i) * 2, 2);
        dst[i] = value != 0;
      }
    }
  };
  // One k-slice of occupancy blurred along i and j, for (i, j) in box: rows of w, h rows.
  std::vector<std::uint16_t> along_i(static_cast<std::size_t>(w) * (h + 2 * R));
  auto blurred_slice = [&](int k, std::vector<std::uint16_t>& slice) {
    slice.assign(static_cast<std::size_t>(w) * h, 0);
    if (k < 0 || k >= shape[2]) return;
    std::fill(along_i.begin(), along_i.end(), 0);
    for (int jj = 0; jj < h + 2 * R; ++jj) {
      const int j = box.lo[1] - R + jj;
      if (j < 0 || j >= shape[1]) continue;
      read_row(j, k);
      std::uint16_t* dst = &along_i[static_cast<std::size_t>(jj) * w];
      for (int t = 0; t <= 2 * R; ++t) {
        const std::uint8_t* src = occupied.data() + t;
        for (int ii = 0; ii < w; ++ii) dst[ii] = std::uint16_t(dst[ii] + kWeights[t] * src[ii]);
      }
    }
    for (int jj = 0; jj < h; ++jj) {
      std::uint16_t* dst = &slice[static_cast<std::size_t>(jj) * w];
      for (int t = 0; t <= 2 * R; ++t) {
        const std::uint16_t* src = &along_i[static_cast<std::size_t>(jj + t) * w];
        for (int ii = 0; ii < w; ++ii) dst[ii] = std::uint16_t(dst[ii] + kWeights[t] * src[ii]);
      }
    }
  };
  // A window of 2R + 1 blurred slices around k.
  std::vector<std::vector<std::uint16_t>> window(2 * R + 1);
  for (int t = 0; t < 2 * R; ++t) blurred_slice(box.lo[2] - R + t, window[t + 1]);
  for (int k = box.lo[2]; k < box.hi[2]; ++k) {
    std::rotate(window.begin(), window.begin() + 1, window.end());
    blurred_slice(k + R, window.back());
    for (int jj = 0; jj < h; ++jj) {
      std::uint8_t* dst = out + packed_index(out_frame, box.lo[0], box.lo[1] + jj, k);
      const std::size_t o = static_cast<std::size_t>(jj) * w;
      for (int ii = 0; ii < w; ++ii) {
        int sum = 0;  // 0..4096
        for (int t = 0; t <= 2 * R; ++t) sum += kWeights[t] * window[t][o + ii];
        dst[ii] = static_cast<std::uint8_t>((sum * 255 + 2048) / 4096);
      }
    }
  }
}

void brick_maxima(const std::uint8_t* smoothed, const VoxelBox& smoothed_frame,
                  const std::array<int, 3>& shape, const VoxelBox& bricks, std::uint8_t* out,
                  const VoxelBox& out_frame) {
  for (int bk = bricks.lo[2]; bk < bricks.hi[2]; ++bk) {
    for (int bj = bricks.lo[1]; bj < bricks.hi[1]; ++bj) {
      for (int bi = bricks.lo[0]; bi < bricks.hi[0]; ++bi) {
        const VoxelBox foot =
            brick_footprints(VoxelBox{{bi, bj, bk}, {bi + 1, bj + 1, bk + 1}}, shape);
        std::uint8_t m = 0;
        for (int k = foot.lo[2]; k < foot.hi[2] && m < 255; ++k) {
          for (int j = foot.lo[1]; j < foot.hi[1]; ++j) {
            const std::uint8_t* row = smoothed + packed_index(smoothed_frame, foot.lo[0], j, k);
            for (int i = 0; i < foot.hi[0] - foot.lo[0]; ++i) m = std::max(m, row[i]);
          }
        }
        out[packed_index(out_frame, bi, bj, bk)] = m;
      }
    }
  }
}

std::array<int, 3> VolumeData::brick_shape() const {
  return {(shape_[0] + kBrickSize - 1) / kBrickSize, (shape_[1] + kBrickSize - 1) / kBrickSize,
          (shape_[2] + kBrickSize - 1) / kBrickSize};
}

const std::vector<std::uint8_t>& VolumeData::smoothed_occupancy() {
  update_derived();
  return smoothed_;
}

const std::vector<std::uint8_t>& VolumeData::brick_max() {
  update_derived();
  return bricks_;
}

void VolumeData::update_derived() {
  if (!derived_ready_) {
    smoothed_.assign(static_cast<std::size_t>(voxel_count()), 0);
    bricks_.assign(static_cast<std::size_t>(brick_shape()[0]) * brick_shape()[1] * brick_shape()[2],
                   0);
    derived_ready_ = true;
    derived_stale_.assign(1, whole(shape_));
  }
  for (const VoxelBox& box : derived_stale_) update_derived_box(box);
  derived_stale_.clear();
}

void VolumeData::mark_derived_stale(const VoxelBox& box) {
  if (!derived_ready_) return;  // computed in full when first read
  derived_stale_.push_back(box);
  if (derived_stale_.size() > kStaleBoxes) {
    VoxelBox all;
    for (const VoxelBox& b : derived_stale_) all = all.united(b);
    derived_stale_.assign(1, all);
  }
}

void VolumeData::update_derived_box(const VoxelBox& box) {
  // A label change reaches the blurred field kSmoothRadius voxels around it, and the brick
  // maxima of the bricks whose footprint meets that.
  const VoxelBox affected = box.grown(kSmoothRadius).clipped(shape_);
  if (affected.empty()) return;
  const int bytes = static_cast<int>(label_bytes(label_type_));
  smooth_occupancy(labels_.data(), whole(shape_), bytes, shape_, affected, smoothed_.data(),
                   whole(shape_));
  brick_maxima(smoothed_.data(), whole(shape_), shape_, bricks_reaching(affected, shape_),
               bricks_.data(), whole(brick_shape()));
}

// ---------------------------------------------------------------------------------------------
// CPU ray cast (the reference the GPU ray caster is tested against)

VolumeHit VolumeData::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                              double iso, double max_distance) {
  update_derived();
  VolumeHit result;
  const double norm = direction.norm();
  if (!(norm > 0.0)) throw ArgumentError("raycast needs a non-zero direction");
  const Eigen::Vector3d d = direction / norm;
  const Eigen::Vector3d s = voxel_size();
  const Eigen::Vector3d u0 = to_voxel_units(origin);
  const Eigen::Vector3d du = d.cwiseQuotient(s);  // voxel units per metre along the ray
  // Enter and leave the grid box [0, n].
  double t0 = 0.0, t1 = max_distance;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(du[a]) < 1e-300) {
      if (u0[a] < 0 || u0[a] > shape_[a]) return result;
      continue;
    }
    double ta = (0 - u0[a]) / du[a], tb = (shape_[a] - u0[a]) / du[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return result;
  const VolumeField field{smoothed_.data(), shape_};
  const double level = iso * 255.0;
  // Samples on the lattice t0 + m * dt, half a voxel apart, as the GPU ray caster takes them.
  const double dt = 0.5 / du.norm();
  const std::int64_t last = static_cast<std::int64_t>(std::floor((t1 - t0) / dt));
  for (std::int64_t m = 0; m <= last; ++m) {
    const double t = t0 + static_cast<double>(m) * dt;
    if (field.sample(u0 + t * du) < level) continue;
    double lo = t0 + static_cast<double>(m - 1) * dt, hi = t;
    for (int it = 0; it < 4 && m > 0; ++it) {
      const double mid = 0.5 * (lo + hi);
      (field.sample(u0 + mid * du) >= level ? hi : lo) = mid;
    }
    const Eigen::Vector3d u = u0 + hi * du;
    result.hit = true;
    result.t = hi;
    result.position = from_voxel_units(u);
    const Eigen::Vector3d g = field.gradient(u, kNormalSpan);
    const Eigen::Vector3d n = (-g).cwiseQuotient(s);
    result.normal = n.norm() > 0 ? n.normalized() : Eigen::Vector3d(-d);
    result.label = visit_labels(label_type_, labels_.data(), [&](auto* p) -> std::uint16_t {
      // As the shader: the voxel a quarter voxel in from the surface along the gradient (the
      // same for every view), else the dominant solid neighbour, else the nearest solid voxel.
      const Eigen::Vector3d inward =
          g.norm() > 1e-12 ? Eigen::Vector3d(g.normalized()) : Eigen::Vector3d(du / du.norm());
      const Eigen::Vector3d in = u + 0.25 * inward;
      const int i = static_cast<int>(std::floor(in.x())), j = static_cast<int>(std::floor(in.y())),
                k = static_cast<int>(std::floor(in.z()));
      if (i >= 0 && j >= 0 && k >= 0 && i < shape_[0] && j < shape_[1] && k < shape_[2]) {
        const std::uint16_t l = p[linear_index(i, j, k)];
        if (l != 0) {
          result.voxel = static_cast<std::int64_t>(linear_index(i, j, k));
          return l;
        }
      }
      const std::uint16_t l = dominant_label(p, shape_, u, &result.voxel);
      return l != 0 ? l : nearest_label(p, shape_, u, &result.voxel);
    });
    return result;
  }
  return result;
}

}  // namespace ambfplus
