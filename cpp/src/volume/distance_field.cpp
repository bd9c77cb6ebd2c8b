#include "ambfplus/volume/distance_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "ambfplus/errors.h"

namespace ambfplus {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

VoxelBox grown_by(const VoxelBox& box, const std::array<int, 3>& margin) {
  VoxelBox out = box;
  for (int a = 0; a < 3; ++a) {
    out.lo[a] -= margin[a];
    out.hi[a] += margin[a];
  }
  return out;
}

VoxelBox intersected(const VoxelBox& a, const VoxelBox& b) {
  VoxelBox out;
  for (int axis = 0; axis < 3; ++axis) {
    out.lo[axis] = std::max(a.lo[axis], b.lo[axis]);
    out.hi[axis] = std::max(out.lo[axis], std::min(a.hi[axis], b.hi[axis]));
  }
  return out;
}

bool contains(const VoxelBox& box, int i, int j, int k) {
  return i >= box.lo[0] && i < box.hi[0] && j >= box.lo[1] && j < box.hi[1] && k >= box.lo[2] &&
         k < box.hi[2];
}

/// One line of the exact squared distance transform: f holds squared distances (metres^2, or
/// infinity) at samples `spacing` metres apart; on return it holds, for each sample, the least
/// f(q) + (spacing * (p - q))^2 over q. v, z and g are scratch of at least n + 1 entries.
void transform_line(double* f, int n, double spacing, int* v, double* z, double* g) {
  // The lower envelope of the parabolas rooted at the finite samples.
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    const double x = spacing * q;
    const double root = f[q] + x * x;
    double s = -kInf;
    while (k >= 0) {
      const double xv = spacing * v[k];
      s = (root - (f[v[k]] + xv * xv)) / (2.0 * (x - xv));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  if (k < 0) return;  // no finite sample: the line stays infinite
  for (int q = 0; q < n; ++q) g[q] = f[q];
  int j = 0;
  for (int q = 0; q < n; ++q) {
    const double x = spacing * q;
    while (z[j + 1] < x) ++j;
    const double d = x - spacing * v[j];
    f[q] = d * d + g[v[j]];
  }
}

/// Squared Euclidean distance from each voxel of a packed box (dims n, i fastest) to the nearest
/// voxel whose `source` flag is set, with per-axis spacing.
void squared_distances(std::vector<double>& f, const std::array<int, 3>& n,
                       const Eigen::Vector3d& spacing) {
  const int longest = std::max({n[0], n[1], n[2]});
  std::vector<int> v(longest + 1);
  std::vector<double> z(longest + 2), g(longest + 1), line(longest);
  const std::size_t stride[3] = {1, static_cast<std::size_t>(n[0]),
                                 static_cast<std::size_t>(n[0]) * n[1]};
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = axis == 0 ? 1 : 0;
    const int a2 = axis == 2 ? 1 : 2;
    for (int y = 0; y < n[a2]; ++y) {
      for (int x = 0; x < n[a1]; ++x) {
        const std::size_t base = x * stride[a1] + y * stride[a2];
        for (int q = 0; q < n[axis]; ++q) line[q] = f[base + q * stride[axis]];
        transform_line(line.data(), n[axis], spacing[axis], v.data(), z.data(), g.data());
        for (int q = 0; q < n[axis]; ++q) f[base + q * stride[axis]] = line[q];
      }
    }
  }
}

}  // namespace

DistanceField::DistanceField(const VolumeData& data, std::vector<std::uint16_t> labels, double band)
    : data_(data), labels_(std::move(labels)), is_member_(65536, false), band_(band) {
  if (labels_.empty()) throw ArgumentError("DistanceField: no label names the structure");
  for (std::uint16_t id : labels_) {
    if (id == 0) throw ArgumentError("DistanceField: label 0 (empty space) is not a structure");
    is_member_[id] = true;
  }
  if (!std::isfinite(band) || band <= 0.0) {
    std::ostringstream message;
    message << "DistanceField: band must be a positive number of metres, got " << band;
    throw ArgumentError(message.str());
  }
  const Eigen::Vector3d s = data_.voxel_size();
  for (int a = 0; a < 3; ++a) {
    reach_[a] = static_cast<int>(std::ceil(band_ / s[a])) + 1;
  }
  rebuild();
}

bool DistanceField::member(int i, int j, int k) const { return is_member_[data_.label(i, j, k)]; }

VoxelBox DistanceField::region_for(const VoxelBox& bounds) const {
  if (bounds.empty()) return VoxelBox{};
  return grown_by(bounds, reach_).clipped(data_.shape());
}

void DistanceField::rebuild() {
  const auto& n = data_.shape();
  VoxelBox bounds{{n[0], n[1], n[2]}, {0, 0, 0}};
  std::int64_t count = 0;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        if (!member(i, j, k)) continue;
        ++count;
        const int c[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          bounds.lo[a] = std::min(bounds.lo[a], c[a]);
          bounds.hi[a] = std::max(bounds.hi[a], c[a] + 1);
        }
      }
    }
  }
  structure_voxels_ = count;
  bounds_ = count ? bounds : VoxelBox{};
  region_ = count ? region_for(bounds) : VoxelBox{};
  values_.assign(static_cast<std::size_t>(region_.count()), static_cast<float>(band_));
  mask_.assign(static_cast<std::size_t>(region_.count()), 0);
  if (count) recompute(region_);
  revision_ = data_.revision();
}

std::int64_t DistanceField::recompute(const VoxelBox& wanted) {
  const VoxelBox out = intersected(wanted, region_);
  if (out.empty()) return 0;
  // Every source that can lie within the band of `out`.
  const VoxelBox src = grown_by(out, reach_).clipped(data_.shape());
  const std::array<int, 3> n{src.hi[0] - src.lo[0], src.hi[1] - src.lo[1], src.hi[2] - src.lo[2]};
  const std::size_t total = static_cast<std::size_t>(n[0]) * n[1] * n[2];
  std::vector<double> outside(total), inside(total);
  bool any_member = false, any_other = false;
  std::size_t idx = 0;
  for (int k = src.lo[2]; k < src.hi[2]; ++k) {
    for (int j = src.lo[1]; j < src.hi[1]; ++j) {
      for (int i = src.lo[0]; i < src.hi[0]; ++i, ++idx) {
        const bool m = member(i, j, k);
        any_member |= m;
        any_other |= !m;
        outside[idx] = m ? 0.0 : kInf;
        inside[idx] = m ? kInf : 0.0;
      }
    }
  }
  const Eigen::Vector3d spacing = data_.voxel_size();
  if (any_member) squared_distances(outside, n, spacing);
  if (any_member && any_other) squared_distances(inside, n, spacing);

  const int rn0 = region_.hi[0] - region_.lo[0];
  const int rn1 = region_.hi[1] - region_.lo[1];
  const float band = static_cast<float>(band_);
  for (int k = out.lo[2]; k < out.hi[2]; ++k) {
    for (int j = out.lo[1]; j < out.hi[1]; ++j) {
      for (int i = out.lo[0]; i < out.hi[0]; ++i) {
        const std::size_t s =
            static_cast<std::size_t>(i - src.lo[0]) +
            static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(j - src.lo[1]) +
                                              static_cast<std::size_t>(n[1]) * (k - src.lo[2]));
        const std::size_t r =
            static_cast<std::size_t>(i - region_.lo[0]) +
            static_cast<std::size_t>(rn0) * (static_cast<std::size_t>(j - region_.lo[1]) +
                                             static_cast<std::size_t>(rn1) * (k - region_.lo[2]));
        const bool m = outside[s] == 0.0;
        const double d = m ? -std::sqrt(inside[s]) : std::sqrt(outside[s]);
        values_[r] = static_cast<float>(std::clamp(d, -band_, band_));
        if (!std::isfinite(d)) values_[r] = m ? -band : band;
        mask_[r] = m ? 1 : 0;
      }
    }
  }
  return out.count();
}

std::int64_t DistanceField::update() {
  if (data_.revision() == revision_) return 0;
  std::vector<VoxelBox> boxes;
  if (!data_.dirty_boxes_since(revision_, &boxes)) {
    revision_ = data_.revision();
    return 0;
  }
  const auto& n = data_.shape();
  const int rn0 = region_.hi[0] - region_.lo[0];
  const int rn1 = region_.hi[1] - region_.lo[1];
  std::vector<VoxelBox> changed;
  std::int64_t delta = 0;
  for (const VoxelBox& dirty : boxes) {
    const VoxelBox box = dirty.clipped(n);
    VoxelBox tight{{n[0], n[1], n[2]}, {0, 0, 0}};
    for (int k = box.lo[2]; k < box.hi[2]; ++k) {
      for (int j = box.lo[1]; j < box.hi[1]; ++j) {
        for (int i = box.lo[0]; i < box.hi[0]; ++i) {
          const bool m = member(i, j, k);
          bool was = false;
          if (contains(region_, i, j, k)) {
            was = mask_[static_cast<std::size_t>(i - region_.lo[0]) +
                        static_cast<std::size_t>(rn0) *
                            (static_cast<std::size_t>(j - region_.lo[1]) +
                             static_cast<std::size_t>(rn1) * (k - region_.lo[2]))] != 0;
          } else if (m) {
            // The structure grew beyond the stored region: build it anew.
            rebuild();
            return region_.count();
          }
          if (m == was) continue;
          delta += m ? 1 : -1;
          const int c[3] = {i, j, k};
          for (int a = 0; a < 3; ++a) {
            tight.lo[a] = std::min(tight.lo[a], c[a]);
            tight.hi[a] = std::max(tight.hi[a], c[a] + 1);
          }
        }
      }
    }
    if (!tight.empty()) {
      changed.push_back(tight);
      bounds_ = bounds_.united(tight);  // still holds every structure voxel
    }
  }
  std::int64_t recomputed = 0;
  for (const VoxelBox& box : changed) recomputed += recompute(grown_by(box, reach_));
  structure_voxels_ += delta;
  revision_ = data_.revision();
  return recomputed;
}

double DistanceField::stored(int i, int j, int k) const {
  if (!contains(region_, i, j, k)) return band_;
  const int rn0 = region_.hi[0] - region_.lo[0];
  const int rn1 = region_.hi[1] - region_.lo[1];
  const float v = values_[static_cast<std::size_t>(i - region_.lo[0]) +
                          static_cast<std::size_t>(rn0) *
                              (static_cast<std::size_t>(j - region_.lo[1]) +
                               static_cast<std::size_t>(rn1) * (k - region_.lo[2]))];
  // Clamped values read back as the band itself, as they do outside the stored region.
  const float band = static_cast<float>(band_);
  return v >= band ? band_ : v <= -band ? -band_ : v;
}

double DistanceField::at(int i, int j, int k) const {
  const auto& n = data_.shape();
  if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) {
    std::ostringstream message;
    message << "DistanceField: voxel (" << i << ", " << j << ", " << k << ") is outside the grid ("
            << n[0] << ", " << n[1] << ", " << n[2] << ")";
    throw OutOfRange(message.str());
  }
  return stored(i, j, k);
}

DistanceSample DistanceField::sample(const Eigen::Vector3d& p) const {
  const auto& n = data_.shape();
  const Eigen::Vector3d u = data_.to_voxel_units(p) - Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d spacing = data_.voxel_size();
  int lo[3];
  double t[3];
  bool free[3];
  for (int a = 0; a < 3; ++a) {
    const double top = n[a] - 1;
    const double c = std::clamp(u[a], 0.0, top);
    free[a] = u[a] >= 0.0 && u[a] <= top && n[a] > 1;
    lo[a] = std::min(static_cast<int>(std::floor(c)), std::max(n[a] - 2, 0));
    t[a] = n[a] > 1 ? c - lo[a] : 0.0;
  }
  double v[2][2][2];
  for (int dk = 0; dk < 2; ++dk) {
    for (int dj = 0; dj < 2; ++dj) {
      for (int di = 0; di < 2; ++di) {
        v[dk][dj][di] = stored(std::min(lo[0] + di, n[0] - 1), std::min(lo[1] + dj, n[1] - 1),
                               std::min(lo[2] + dk, n[2] - 1));
      }
    }
  }
  auto lerp = [](double a, double b, double w) { return a + (b - a) * w; };
  // Along i first, then j, then k; the derivatives of the same interpolant.
  double x[2][2], dx[2][2];
  for (int dk = 0; dk < 2; ++dk) {
    for (int dj = 0; dj < 2; ++dj) {
      x[dk][dj] = lerp(v[dk][dj][0], v[dk][dj][1], t[0]);
      dx[dk][dj] = v[dk][dj][1] - v[dk][dj][0];
    }
  }
  double y[2], dyi[2], dyj[2];
  for (int dk = 0; dk < 2; ++dk) {
    y[dk] = lerp(x[dk][0], x[dk][1], t[1]);
    dyi[dk] = lerp(dx[dk][0], dx[dk][1], t[1]);
    dyj[dk] = x[dk][1] - x[dk][0];
  }
  DistanceSample s;
  s.distance = lerp(y[0], y[1], t[2]);
  const double di = lerp(dyi[0], dyi[1], t[2]);
  const double dj = lerp(dyj[0], dyj[1], t[2]);
  const double dk = y[1] - y[0];
  s.gradient = Eigen::Vector3d(free[0] ? di / spacing[0] : 0.0, free[1] ? dj / spacing[1] : 0.0,
                               free[2] ? dk / spacing[2] : 0.0);
  return s;
}

std::vector<float> DistanceField::values() const {
  const auto& n = data_.shape();
  std::vector<float> out(static_cast<std::size_t>(data_.voxel_count()));
  std::size_t idx = 0;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) out[idx++] = static_cast<float>(stored(i, j, k));
    }
  }
  return out;
}

}  // namespace ambfplus
