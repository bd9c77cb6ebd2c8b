#include "render/volume_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "ambfplus/render/render_stats.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"
#include "render/scene_renderer.h"

namespace ambfplus::render {
namespace {

// Boxes a stage copies at most, and the voxels a merge may add for one box fewer.
constexpr std::size_t kStagedBoxes = 8;
constexpr std::int64_t kStagingSlack = 4096;

// The intensity grid as 0..255 between its 2nd and 98th percentiles over the labelled voxels
// (over all voxels where none is labelled): the albedo the looks give a volume with CT data.
std::vector<std::uint8_t> normalized_intensity(VolumeData& data) {
  const std::size_t n = static_cast<std::size_t>(data.voxel_count());
  const bool int16 = data.intensity_type() == IntensityType::kInt16;
  const void* raw = data.intensity_data();
  auto value = [&](std::size_t i) {
    return int16 ? float(static_cast<const std::int16_t*>(raw)[i])
                 : static_cast<const float*>(raw)[i];
  };
  const bool wide = data.label_type() == LabelType::kUInt16;
  auto labelled = [&](std::size_t i) {
    return wide ? static_cast<const std::uint16_t*>(data.label_data())[i] != 0
                : static_cast<const std::uint8_t*>(data.label_data())[i] != 0;
  };
  // A strided sample of about a million voxels is enough for two percentiles.
  const std::size_t stride = std::max<std::size_t>(1, n / 1000000);
  std::vector<float> sample;
  for (std::size_t i = 0; i < n; i += stride) {
    if (labelled(i)) sample.push_back(value(i));
  }
  if (sample.empty()) {
    for (std::size_t i = 0; i < n; i += stride) sample.push_back(value(i));
  }
  auto percentile = [&](double q) {
    auto at = sample.begin() + static_cast<std::ptrdiff_t>(q * double(sample.size() - 1));
    std::nth_element(sample.begin(), at, sample.end());
    return *at;
  };
  const float lo = percentile(0.02), hi = std::max(percentile(0.98), lo + 1e-6f);
  std::vector<std::uint8_t> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float t = std::clamp((value(i) - lo) / (hi - lo), 0.0f, 1.0f);
    out[i] = static_cast<std::uint8_t>(t * 255.0f + 0.5f);
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> brick_distances(const std::vector<std::uint8_t>& brick_max,
                                          const std::array<int, 3>& n, double level) {
  std::vector<std::uint8_t> d(brick_max.size());
  for (std::size_t v = 0; v < d.size(); ++v) d[v] = brick_max[v] >= level ? 0 : 255;
  auto at = [&](int i, int j, int k) -> std::uint8_t& {
    return d[static_cast<std::size_t>(i) +
             std::size_t(n[0]) * (std::size_t(j) + std::size_t(n[1]) * k)];
  };
  // Two raster passes over the 26-neighbourhood give the exact chessboard distance.
  auto relax = [&](int i, int j, int k, int sign) {
    std::uint8_t& here = at(i, j, k);
    if (here == 0) return;
    for (int dk = -1; dk <= 1; ++dk) {
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          // Neighbours already visited in this pass's order.
          const int order = dk != 0 ? dk : dj != 0 ? dj : di;
          if (order * sign >= 0) continue;
          const int a = i + di, b = j + dj, c = k + dk;
          if (a < 0 || b < 0 || c < 0 || a >= n[0] || b >= n[1] || c >= n[2]) continue;
          const int candidate = at(a, b, c) + 1;
          if (candidate < here) here = static_cast<std::uint8_t>(candidate);
        }
      }
    }
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) relax(i, j, k, +1);
  for (int k = n[2] - 1; k >= 0; --k)
    for (int j = n[1] - 1; j >= 0; --j)
      for (int i = n[0] - 1; i >= 0; --i) relax(i, j, k, -1);
  return d;
}

void coalesce_boxes(std::vector<VoxelBox>& boxes, int margin, std::size_t max_boxes,
                    std::int64_t slack) {
  auto grown = [margin](const VoxelBox& b) { return b.grown(margin).count(); };
  // Voxels the grown copy of a ∪ b holds beyond those of a and b apart.
  auto extra = [&](const VoxelBox& a, const VoxelBox& b) {
    return grown(a.united(b)) - grown(a) - grown(b);
  };
  std::size_t kept = 0;  // boxes[0, kept) are the merged ones
  for (std::size_t n = 0; n < boxes.size(); ++n) {
    const VoxelBox box = boxes[n];
    if (box.empty()) continue;
    std::size_t best = kept;
    std::int64_t best_extra = 0;
    for (std::size_t m = 0; m < kept; ++m) {
      const std::int64_t e = extra(boxes[m], box);
      if (best == kept || e < best_extra) {
        best = m;
        best_extra = e;
      }
    }
    if (best == kept || (best_extra > slack && kept < max_boxes)) {
      boxes[kept++] = box;
    } else {
      boxes[best] = boxes[best].united(box);
    }
  }
  boxes.resize(kept);
  // A box that grew may now overlap another: join pairs that cost little, until none does.
  for (bool joined = true; joined;) {
    joined = false;
    for (std::size_t a = 0; a < boxes.size() && !joined; ++a) {
      for (std::size_t b = a + 1; b < boxes.size(); ++b) {
        if (extra(boxes[a], boxes[b]) <= slack) {
          boxes[a] = boxes[a].united(boxes[b]);
          boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(b));
          joined = true;
          break;
        }
      }
    }
  }
}

std::array<int, 3> obscurance_cells(const std::array<int, 3>& shape) {
  constexpr int C = kObscuranceCell;
  return {(shape[0] + C - 1) / C, (shape[1] + C - 1) / C, (shape[2] + C - 1) / C};
}

void count_cell_occupancy(const std::uint8_t* labels, const VoxelBox& frame, int bytes,
                          const std::array<int, 3>& shape, const VoxelBox& cells,
                          std::uint8_t* counts) {
  constexpr int C = kObscuranceCell;
  const auto n = obscurance_cells(shape);
  const std::size_t w = static_cast<std::size_t>(frame.hi[0] - frame.lo[0]);
  const std::size_t h = static_cast<std::size_t>(frame.hi[1] - frame.lo[1]);
  auto solid = [&](int i, int j, int k) {
    const std::size_t at = static_cast<std::size_t>(i - frame.lo[0]) +
                           w * (static_cast<std::size_t>(j - frame.lo[1]) + h * (k - frame.lo[2]));
    if (bytes == 1) return labels[at] != 0;
    std::uint16_t value = 0;
    std::memcpy(&value, labels + at * 2, 2);
    return value != 0;
  };
  for (int ck = cells.lo[2]; ck < cells.hi[2]; ++ck) {
    for (int cj = cells.lo[1]; cj < cells.hi[1]; ++cj) {
      for (int ci = cells.lo[0]; ci < cells.hi[0]; ++ci) {
        int count = 0;
        for (int k = ck * C; k < std::min(shape[2], ck * C + C); ++k)
          for (int j = cj * C; j < std::min(shape[1], cj * C + C); ++j)
            for (int i = ci * C; i < std::min(shape[0], ci * C + C); ++i) count += solid(i, j, k);
        counts[static_cast<std::size_t>(ci) +
               std::size_t(n[0]) * (std::size_t(cj) + std::size_t(n[1]) * ck)] =
            static_cast<std::uint8_t>(count);
      }
    }
  }
}

std::vector<std::uint8_t> blur_cell_occupancy(const std::vector<std::uint8_t>& counts,
                                              const std::array<int, 3>& n, const VoxelBox& cells) {
  constexpr int R = kObscuranceReach;
  constexpr int C3 = kObscuranceCell * kObscuranceCell * kObscuranceCell;
  float weights[2 * R + 1];
  float total = 0.0f;
  for (int t = -R; t <= R; ++t) {
    weights[t + R] =
        static_cast<float>(std::exp(-0.5 * t * t / (kObscuranceSigma * kObscuranceSigma)));
    total += weights[t + R];
  }
  for (float& w : weights) w /= total;
  // Separable: along k over the box grown along i and j, then along j, then along i; cells
  // outside the grid are empty.
  const VoxelBox b = cells;
  const int gi0 = b.lo[0] - R, gi1 = b.hi[0] + R, gj0 = b.lo[1] - R, gj1 = b.hi[1] + R;
  const int wi = gi1 - gi0, wj = gj1 - gj0, wk = b.hi[2] - b.lo[2], hj = b.hi[1] - b.lo[1];
  auto count_at = [&](int i, int j, int k) -> float {
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return 0.0f;
    return counts[static_cast<std::size_t>(i) +
                  std::size_t(n[0]) * (std::size_t(j) + std::size_t(n[1]) * k)];
  };
  std::vector<float> along_k(static_cast<std::size_t>(wi) * wj * wk);
  for (int k = 0; k < wk; ++k)
    for (int j = 0; j < wj; ++j)
      for (int i = 0; i < wi; ++i) {
        float sum = 0.0f;
        for (int t = -R; t <= R; ++t)
          sum += weights[t + R] * count_at(gi0 + i, gj0 + j, b.lo[2] + k + t);
        along_k[static_cast<std::size_t>(i) + std::size_t(wi) * (j + std::size_t(wj) * k)] = sum;
      }
  std::vector<float> along_j(static_cast<std::size_t>(wi) * hj * wk);
  for (int k = 0; k < wk; ++k)
    for (int j = 0; j < hj; ++j)
      for (int i = 0; i < wi; ++i) {
        float sum = 0.0f;
        for (int t = 0; t <= 2 * R; ++t) {
          sum += weights[t] * along_k[static_cast<std::size_t>(i) +
                                      std::size_t(wi) * (j + t + std::size_t(wj) * k)];
        }
        along_j[static_cast<std::size_t>(i) + std::size_t(wi) * (j + std::size_t(hj) * k)] = sum;
      }
  const int w = b.hi[0] - b.lo[0];
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * hj * wk);
  for (int k = 0; k < wk; ++k)
    for (int j = 0; j < hj; ++j)
      for (int i = 0; i < w; ++i) {
        float sum = 0.0f;
        const float* row = &along_j[std::size_t(wi) * (j + std::size_t(hj) * k)];
        for (int t = 0; t <= 2 * R; ++t) sum += weights[t] * row[i + t];
        out[static_cast<std::size_t>(i) + std::size_t(w) * (j + std::size_t(hj) * k)] =
            static_cast<std::uint8_t>(std::clamp(sum / C3, 0.0f, 1.0f) * 255.0f + 0.5f);
      }
  return out;
}

namespace {

GLuint make_texture_3d(GLenum filter, GLenum wrap) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_3D, t);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, filter);
  for (GLenum axis : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) {
    glTexParameteri(GL_TEXTURE_3D, axis, wrap);
  }
  const GLfloat border[4] = {0, 0, 0, 0};
  glTexParameterfv(GL_TEXTURE_3D, GL_TEXTURE_BORDER_COLOR, border);
  return t;
}

// Copies `box` out of a packed box `frame` of a grid (i fastest, `bytes` per element), packed.
std::vector<std::uint8_t> pack_box(const void* grid, const VoxelBox& frame, const VoxelBox& box,
                                   int bytes) {
  const auto* src = static_cast<const std::uint8_t*>(grid);
  const std::size_t row = static_cast<std::size_t>(box.hi[0] - box.lo[0]) * bytes;
  const std::size_t w = static_cast<std::size_t>(frame.hi[0] - frame.lo[0]);
  const std::size_t h = static_cast<std::size_t>(frame.hi[1] - frame.lo[1]);
  std::vector<std::uint8_t> out(row * (box.hi[1] - box.lo[1]) * (box.hi[2] - box.lo[2]));
  std::uint8_t* dst = out.data();
  for (int k = box.lo[2]; k < box.hi[2]; ++k) {
    for (int j = box.lo[1]; j < box.hi[1]; ++j, dst += row) {
      const std::size_t at =
          (static_cast<std::size_t>(box.lo[0] - frame.lo[0]) +
           w * (static_cast<std::size_t>(j - frame.lo[1]) + h * (k - frame.lo[2]))) *
          bytes;
      std::memcpy(dst, src + at, row);
    }
  }
  return out;
}

// Writes a packed box back into a grid stored i fastest with `shape` (1 byte per element).
void unpack_box(const std::vector<std::uint8_t>& bytes, const std::array<int, 3>& shape,
                const VoxelBox& box, std::uint8_t* grid) {
  const std::size_t row = static_cast<std::size_t>(box.hi[0] - box.lo[0]);
  const std::uint8_t* src = bytes.data();
  for (int k = box.lo[2]; k < box.hi[2]; ++k) {
    for (int j = box.lo[1]; j < box.hi[1]; ++j, src += row) {
      std::memcpy(
          grid + static_cast<std::size_t>(box.lo[0]) +
              static_cast<std::size_t>(shape[0]) * (j + static_cast<std::size_t>(shape[1]) * k),
          src, row);
    }
  }
}

// Sends a packed box to a 3D texture.
void upload_box(GLuint texture, const VoxelBox& box, GLenum format, GLenum type,
                const std::vector<std::uint8_t>& bytes) {
  if (box.empty()) return;
  glBindTexture(GL_TEXTURE_3D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage3D(GL_TEXTURE_3D, 0, box.lo[0], box.lo[1], box.lo[2], box.hi[0] - box.lo[0],
                  box.hi[1] - box.lo[1], box.hi[2] - box.lo[2], format, type, bytes.data());
}

// The 36 corners of the unit cube's 12 triangles, counter-clockwise seen from outside.
const float kCube[] = {
    0, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 1, 0, 0,  // z = 0
    0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1,  // z = 1
    0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1,  // y = 0
    0, 1, 0, 0, 1, 1, 1, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1, 0,  // y = 1
    0, 0, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 1, 0,  // x = 0
    1, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 0, 1, 1, 1, 1, 0, 1,  // x = 1
};

}  // namespace

GpuVolume::GpuVolume(std::shared_ptr<VolumeData> data) : data_(std::move(data)) {}

void GpuVolume::create_textures() {
  const auto& n = data_->shape();
  occupancy_ = make_texture_3d(GL_LINEAR, GL_CLAMP_TO_BORDER);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_R8, n[0], n[1], n[2], 0, GL_RED, GL_UNSIGNED_BYTE, nullptr);
  labels_ = make_texture_3d(GL_NEAREST, GL_CLAMP_TO_EDGE);
  const bool wide = data_->label_type() == LabelType::kUInt16;
  glTexImage3D(GL_TEXTURE_3D, 0, wide ? GL_R16UI : GL_R8UI, n[0], n[1], n[2], 0, GL_RED_INTEGER,
               wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, nullptr);
  const auto b = data_->brick_shape();
  bricks_ = make_texture_3d(GL_NEAREST, GL_CLAMP_TO_EDGE);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, b[0], b[1], b[2], 0, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
               nullptr);
  glGenTextures(1, &colors_);
  glBindTexture(GL_TEXTURE_2D, colors_);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof(kCube), kCube, GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glBindVertexArray(0);
  check_gl("creating volume textures");
}

GpuVolume::~GpuVolume() {
  if (vao_ == 0) return;  // never uploaded
  const GLuint textures[6] = {occupancy_, labels_, bricks_, colors_, intensity_, obscurance_};
  glDeleteTextures(6, textures);  // zeros are ignored
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
}

void GpuVolume::stage_colors(Pending& pending) {
  const LabelTable& table = data_->label_table();
  if (table.labels().size() == staged_table_.size() &&
      std::equal(staged_table_.begin(), staged_table_.end(), table.labels().begin(),
                 [](const Label& a, const Label& b) {
                   return a.id == b.id && a.color == b.color && a.name == b.name;
                 })) {
    return;
  }
  // RGB: the label's colour; alpha: 255 where the looks' bone texture applies (is_bone).
  pending.color_rows = table.max_id() / 256 + 1;
  pending.colors.assign(static_cast<std::size_t>(pending.color_rows) * 256 * 4, 255);
  for (const Label& l : table.labels()) {
    for (int c = 0; c < 3; ++c) pending.colors[l.id * 4 + c] = l.color[c];
    pending.colors[l.id * 4 + 3] = is_bone(table, l) ? 255 : 0;
  }
  staged_table_ = table.labels();
}

void GpuVolume::stage(double iso) {
  const auto start = std::chrono::steady_clock::now();
  Pending pending;
  stage_colors(pending);
  const bool first = revision_ < 0;
  const auto& n = data_->shape();
  if (first) {
    boxes_.assign(1, VoxelBox{{0, 0, 0}, n});
  } else if (!data_->dirty_boxes_since(revision_, &boxes_)) {
    boxes_.clear();
  }
  // Few boxes: each costs allocations and a pass over its rows, under the world's lock.
  coalesce_boxes(boxes_, VolumeData::kSmoothRadius, kStagedBoxes, kStagingSlack);
  // Bricks that may hold the surface: those whose largest value can reach the level (one step
  // of 8-bit filtering below it, so rounding never hides a surface).
  pending.level = std::max(0.0, iso * 255.0 - 1.0);
  const int bytes = data_->label_type() == LabelType::kUInt16 ? 2 : 1;
  // Copies only: upload() derives the smoothed occupancy and brick maxima from these labels
  // off the lock. A label change reaches the smoothed field kSmoothRadius voxels around it,
  // and the maxima of the bricks whose footprint meets that, which need the smoothed field
  // over their whole footprints, which needs the labels kSmoothRadius around those.
  for (const VoxelBox& box : boxes_) {
    if (box.empty()) continue;
    Region region;
    region.edited = box;
    region.grown = box.grown(VolumeData::kSmoothRadius).clipped(n);
    region.bricks = bricks_reaching(region.grown, n);
    region.footprints = brick_footprints(region.bricks, n);
    region.frame = region.footprints.grown(VolumeData::kSmoothRadius).clipped(n);
    region.labels = pack_box(data_->label_data(), VoxelBox{{0, 0, 0}, n}, region.frame, bytes);
    pending.regions.push_back(std::move(region));
  }
  revision_ = data_->revision();
  const bool level_changed = pending.level != staged_level_;
  staged_level_ = pending.level;
  // The intensity grid when it is new or was changed (drilling edits labels, never the CT).
  const bool intensity_changed = data_->intensity_revision() != staged_intensity_;
  if (intensity_changed) {
    if (data_->intensity_type() != IntensityType::kNone) {
      pending.intensity = normalized_intensity(*data_);
    } else {
      pending.drop_intensity = !first;
    }
    staged_intensity_ = data_->intensity_revision();
  }
  if (boxes_.empty() && pending.colors.empty() && !level_changed && pending.intensity.empty() &&
      !pending.drop_intensity) {
    return;
  }
  pending.full = first;
  pending.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.push_back(std::move(pending));
}

void GpuVolume::derive(const Region& region, int bytes, Derived& out) const {
  const auto& n = data_->shape();
  const VoxelBox& footprints = region.footprints;
  std::vector<std::uint8_t> smoothed(static_cast<std::size_t>(footprints.count()));
  smooth_occupancy(region.labels.data(), region.frame, bytes, n, footprints, smoothed.data(),
                   footprints);
  out.labels.push_back(
      {region.edited, pack_box(region.labels.data(), region.frame, region.edited, bytes)});
  out.occupancy.push_back({region.grown, pack_box(smoothed.data(), footprints, region.grown, 1)});
  std::vector<std::uint8_t> maxima(static_cast<std::size_t>(region.bricks.count()));
  brick_maxima(smoothed.data(), footprints, n, region.bricks, maxima.data(), region.bricks);
  out.brick_max.push_back({region.bricks, std::move(maxima)});
}

void GpuVolume::update_distances(const std::vector<Box>& brick_boxes, double level, bool full) {
  const auto b = data_->brick_shape();
  if (brick_max_.empty()) {
    brick_max_.assign(static_cast<std::size_t>(b[0]) * b[1] * b[2], 0);
    full = true;
  }
  for (const Box& box : brick_boxes) unpack_box(box.bytes, b, box.box, brick_max_.data());
  full = full || level != distance_level_ || distances_.size() != brick_max_.size();
  auto at = [&](int i, int j, int k) {
    return static_cast<std::size_t>(i) +
           std::size_t(b[0]) * (std::size_t(j) + std::size_t(b[1]) * k);
  };
  // Removing material only empties bricks, which leaves every other distance a safe lower
  // bound: mark emptied bricks 1 and keep the rest. A brick that filled needs the full map.
  for (std::size_t n = 0; n < brick_boxes.size() && !full; ++n) {
    const VoxelBox& bricks = brick_boxes[n].box;
    for (int k = bricks.lo[2]; k < bricks.hi[2] && !full; ++k)
      for (int j = bricks.lo[1]; j < bricks.hi[1] && !full; ++j)
        for (int i = bricks.lo[0]; i < bricks.hi[0]; ++i) {
          const std::size_t v = at(i, j, k);
          const bool occupied = brick_max_[v] >= level;
          if (occupied && distances_[v] != 0) {
            full = true;
            break;
          }
          if (!occupied && distances_[v] == 0) distances_[v] = 1;
        }
  }
  distance_level_ = level;
  if (full) {
    distances_ = brick_distances(brick_max_, b, level);
    const VoxelBox all{{0, 0, 0}, b};
    upload_box(bricks_, all, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
               pack_box(distances_.data(), all, all, 1));
    return;
  }
  for (const Box& box : brick_boxes) {
    upload_box(bricks_, box.box, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
               pack_box(distances_.data(), VoxelBox{{0, 0, 0}, b}, box.box, 1));
  }
}

void GpuVolume::upload() {
  std::vector<Pending> pending;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending.swap(pending_);
  }
  if (pending.empty()) return;
  ++generation_;
  const auto start = std::chrono::steady_clock::now();
  const bool created = vao_ == 0;
  if (created) create_textures();
  const bool wide = data_->label_type() == LabelType::kUInt16;
  VolumeUpload stats;
  for (const Pending& p : pending) {
    if (!p.colors.empty()) {
      glBindTexture(GL_TEXTURE_2D, colors_);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 256, p.color_rows, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                   p.colors.data());
    }
    if (p.drop_intensity && intensity_ != 0) {
      glDeleteTextures(1, &intensity_);
      intensity_ = 0;
    }
    if (!p.intensity.empty()) {
      if (intensity_ == 0) intensity_ = make_texture_3d(GL_LINEAR, GL_CLAMP_TO_EDGE);
      const auto& n = data_->shape();
      glBindTexture(GL_TEXTURE_3D, intensity_);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage3D(GL_TEXTURE_3D, 0, GL_R8, n[0], n[1], n[2], 0, GL_RED, GL_UNSIGNED_BYTE,
                   p.intensity.data());
    }
    Derived derived;
    const auto cell_shape = obscurance_cells(data_->shape());
    if (cell_counts_.empty()) {
      cell_counts_.assign(std::size_t(cell_shape[0]) * cell_shape[1] * cell_shape[2], 0);
    }
    for (const Region& region : p.regions) {
      derive(region, wide ? 2 : 1, derived);
      // The cells the edit touched: the frame holds their voxels (it holds whole bricks, and
      // a brick is whole cells).
      VoxelBox cells;
      for (int a = 0; a < 3; ++a) {
        cells.lo[a] = region.edited.lo[a] / kObscuranceCell;
        cells.hi[a] = (region.edited.hi[a] + kObscuranceCell - 1) / kObscuranceCell;
      }
      count_cell_occupancy(region.labels.data(), region.frame, wide ? 2 : 1, data_->shape(), cells,
                           cell_counts_.data());
      if (obscurance_ != 0) update_obscurance(cells);
    }
    for (const Box& box : derived.labels) {
      upload_box(labels_, box.box, GL_RED_INTEGER, wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE,
                 box.bytes);
      stats.voxels += box.box.count();
    }
    for (const Box& box : derived.occupancy) {
      upload_box(occupancy_, box.box, GL_RED, GL_UNSIGNED_BYTE, box.bytes);
    }
    update_distances(derived.brick_max, p.level, p.full || created);
    stats.full = stats.full || p.full;
    stats.seconds += p.seconds;
  }
  check_gl("uploading a volume");
  stats.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  last_upload_ = stats;
}

void GpuVolume::update_obscurance(const VoxelBox& cells) {
  const auto n = obscurance_cells(data_->shape());
  VoxelBox box = cells.grown(kObscuranceReach).clipped(n);
  if (obscurance_ == 0) {
    obscurance_ = make_texture_3d(GL_LINEAR, GL_CLAMP_TO_BORDER);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R8, n[0], n[1], n[2], 0, GL_RED, GL_UNSIGNED_BYTE, nullptr);
    box = VoxelBox{{0, 0, 0}, n};
  }
  upload_box(obscurance_, box, GL_RED, GL_UNSIGNED_BYTE, blur_cell_occupancy(cell_counts_, n, box));
}

VolumeUpload GpuVolume::last_upload() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_upload_;
}

void GpuVolume::draw(const Snapshot::Volume& volume, const Eigen::Isometry3d& view,
                     const Eigen::Matrix4d& projection, unsigned passes, const LightSet& lights,
                     const SurfacePass& pass) {
  const std::string defines =
      lights.defines() + "#define EMPTY_SPACE_SKIPPING " + (volume.skipping ? "1" : "0") + "\n" +
      ((passes & kPassRgb) ? "#define SHADE 1\n" : "#define SHADE 0\n") +
      ((passes & kPassRgb) && volume.looks ? "#define LOOKS 1\n" : "") +
      (pass.orthographic ? "#define ORTHOGRAPHIC 1\n" : "") +
      (pass.packed ? "#define FROM_PIXELS 1\n" : "") + pass.defines +
      (std::getenv("AMBFPLUS_DEBUG_VOLUME_STEPS") ? "#define DEBUG_STEPS 1\n" : "");
  Program& program = Context::get().program(pass.packed ? "supersample_packed.vert" : "volume.vert",
                                            "volume.frag", defines);
  program.use();
  const Eigen::Vector3d s = data_->voxel_size();
  Eigen::Matrix4d volume_from_voxel = Eigen::Matrix4d::Identity();
  volume_from_voxel.topLeftCorner<3, 3>() = s.asDiagonal();
  volume_from_voxel.topRightCorner<3, 1>() = -data_->dimensions() / 2;
  const Eigen::Matrix4d camera_from_voxel =
      view.inverse().matrix() * volume.pose.matrix() * volume_from_voxel;
  const Eigen::Matrix4d clip_from_voxel = projection * camera_from_voxel;
  const Eigen::Matrix4d voxel_from_camera = camera_from_voxel.inverse();
  const Eigen::Vector3d eye = (voxel_from_camera * Eigen::Vector4d(0, 0, 0, 1)).head<3>();
  const Eigen::Matrix3d normal_from_voxel =
      camera_from_voxel.topLeftCorner<3, 3>().inverse().transpose();
  const auto& n = data_->shape();
  const bool looks = (passes & kPassRgb) && volume.looks;
  if (looks && obscurance_ == 0) update_obscurance(VoxelBox{{0, 0, 0}, obscurance_cells(n)});
  if (pass.orthographic) {
    // Rays along the view's z, starting behind the box by more than its diagonal.
    const Eigen::Vector3d dir = (voxel_from_camera * Eigen::Vector4d(0, 0, 1, 0)).head<3>();
    const Eigen::Vector3d dir_unit = dir.normalized();
    glUniform3f(program.uniform("u_ray_dir"), float(dir_unit.x()), float(dir_unit.y()),
                float(dir_unit.z()));
    glUniform1f(program.uniform("u_ray_back"),
                float(2.0 * Eigen::Vector3d(n[0], n[1], n[2]).norm() + 1.0));
  }
  if (pass.packed) {
    const Eigen::Matrix4f voxel_from_clip = clip_from_voxel.inverse().cast<float>();
    glUniformMatrix4fv(program.uniform("u_voxel_from_clip"), 1, GL_FALSE, voxel_from_clip.data());
  }
  const Eigen::Matrix4f clip_f = clip_from_voxel.cast<float>();
  const Eigen::Matrix4f camera_f = camera_from_voxel.cast<float>();
  const Eigen::Matrix3f normal_f = normal_from_voxel.cast<float>();
  glUniform3f(program.uniform("u_shape"), float(n[0]), float(n[1]), float(n[2]));
  glUniform3f(program.uniform("u_voxel_size"), float(s.x()), float(s.y()), float(s.z()));
  glUniform3f(program.uniform("u_eye"), float(eye.x()), float(eye.y()), float(eye.z()));
  glUniformMatrix4fv(program.uniform("u_clip_from_voxel"), 1, GL_FALSE, clip_f.data());
  glUniformMatrix4fv(program.uniform("u_camera_from_voxel"), 1, GL_FALSE, camera_f.data());
  glUniformMatrix3fv(program.uniform("u_normal_from_voxel"), 1, GL_FALSE, normal_f.data());
  glUniform1f(program.uniform("u_level"), static_cast<float>(volume.iso));
  glUniform1i(program.uniform("u_brick_size"), VolumeData::kBrickSize);
  glUniform1f(program.uniform("u_ambient"), 0.2f);
  glUniform1f(program.uniform("u_specular"), volume.specular);
  glUniform1f(program.uniform("u_shininess"), volume.shininess);
  glUniform1i(program.uniform("u_instance"), volume.id);
  glUniform1i(program.uniform("u_has_intensity"), intensity_ != 0 ? 1 : 0);
  const auto cells = obscurance_cells(n);
  glUniform3f(program.uniform("u_obscurance_scale"), 1.0f / float(kObscuranceCell * cells[0]),
              1.0f / float(kObscuranceCell * cells[1]), 1.0f / float(kObscuranceCell * cells[2]));
  lights.upload(program);
  const struct {
    const char* name;
    GLenum target;
    GLuint texture;
  } units[6] = {
      {"u_occupancy", GL_TEXTURE_3D, occupancy_}, {"u_labels", GL_TEXTURE_3D, labels_},
      {"u_bricks", GL_TEXTURE_3D, bricks_},       {"u_colors", GL_TEXTURE_2D, colors_},
      {"u_intensity", GL_TEXTURE_3D, intensity_}, {"u_obscurance", GL_TEXTURE_3D, obscurance_}};
  for (int u = 0; u < 6; ++u) {
    glActiveTexture(GL_TEXTURE0 + u);
    glBindTexture(units[u].target, units[u].texture);
    glUniform1i(program.uniform(units[u].name), u);
  }
  glActiveTexture(GL_TEXTURE0);
  if (pass.setup) pass.setup(program);
  if (pass.packed) {
    glBindVertexArray(vao_);  // (the triangle's corners come from gl_VertexID)
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    check_gl("ray casting a volume's samples");
    return;
  }
  // One fragment per covered pixel, also with the camera inside the box: draw the back faces.
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 36);
  glBindVertexArray(0);
  glDisable(GL_CULL_FACE);
  check_gl("ray casting a volume");
}

}  // namespace ambfplus::render

namespace ambfplus {

VolumeUploadStats last_volume_upload(const Volume& volume) {
  VolumeUploadStats stats;
  const auto upload =
      static_cast<render::SceneRenderer&>(render::renderer_of(volume.world())).last_upload(volume);
  if (!upload) return stats;
  stats.rendered = true;
  stats.full = upload->full;
  stats.voxels = upload->voxels;
  stats.seconds = upload->seconds;
  return stats;
}

}  // namespace ambfplus
