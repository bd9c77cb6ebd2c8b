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

/// One line of the exact squared distance transform: f[q * stride] (q < n) holds squared
/// distances (metres^2, or infinity) at samples `spacing` metres apart; on return each holds the
/// least f(q) + (spacing * (p - q))^2 over q. v, z and g are scratch of at least n + 1 entries.
void transform_line(double* f, std::ptrdiff_t stride, int n, double spacing, int* v, double* z,
                    double* g) {
  // The lower envelope of the parabolas rooted at the finite samples.
  int k = -1;
  for (int q = 0; q < n; ++q) {
    const double fq = f[q * stride];
    if (fq == kInf) continue;
    const double x = spacing * q;
    const double root = fq + x * x;
    double s = -kInf;
    while (k >= 0) {
      const double xv = spacing * v[k];
      s = (root - (g[k] + xv * xv)) / (2.0 * (x - xv));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    g[k] = fq;  // the root's value, kept beside it
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  if (k < 0) return;  // no finite sample: the line stays infinite
  int j = 0;
  for (int q = 0; q < n; ++q) {
    const double x = spacing * q;
    while (z[j + 1] < x) ++j;
    const double d = x - spacing * v[j];
    f[q * stride] = d * d + g[j];
  }
}

/// Lines transformed side by side: a tile of kTile neighbouring lines, gathered so that each
/// step along the lines reads kTile consecutive values (one or two cache lines) instead of one
/// value a row or a slice away.
constexpr int kTile = 16;

/// Squared Euclidean distance (stored as float: it is rounded to float in the end anyway) from
/// each voxel of a packed box (dims n, i fastest) to the nearest source, a voxel holding 0 (the
/// others hold infinity), with per-axis spacing. The sources lie in [lo, hi) (box coordinates):
/// the first pass visits only the rows through that box and the second only its slices, since
/// every other line holds no source then.
void squared_distances(std::vector<float>& f, const std::array<int, 3>& n,
                       const Eigen::Vector3d& spacing, const std::array<int, 3>& lo,
                       const std::array<int, 3>& hi) {
  const int longest = std::max({n[0], n[1], n[2]});
  std::vector<int> v(longest + 1);
  std::vector<double> z(longest + 2), g(longest + 1);
  std::vector<double> tile(static_cast<std::size_t>(longest) * kTile);
  const std::size_t row = static_cast<std::size_t>(n[0]);
  const std::size_t slice = row * n[1];
  // Along i: contiguous rows.
  for (int k = lo[2]; k < hi[2]; ++k) {
    for (int j = lo[1]; j < hi[1]; ++j) {
      float* line = f.data() + j * row + k * slice;
      for (int q = 0; q < n[0]; ++q) tile[q] = line[q];
      transform_line(tile.data(), 1, n[0], spacing[0], v.data(), z.data(), g.data());
      for (int q = 0; q < n[0]; ++q) line[q] = static_cast<float>(tile[q]);
    }
  }
  // Along j and then k, kTile lines at a time.
  auto tiled = [&](int axis, std::size_t step, std::size_t base) {
    for (int i0 = 0; i0 < n[0]; i0 += kTile) {
      const int count = std::min(kTile, n[0] - i0);
      float* first = f.data() + base + i0;
      for (int q = 0; q < n[axis]; ++q) {
        const float* in = first + q * step;
        double* out = tile.data() + static_cast<std::size_t>(q) * kTile;
        for (int b = 0; b < count; ++b) out[b] = in[b];
      }
      for (int b = 0; b < count; ++b) {
        transform_line(tile.data() + b, kTile, n[axis], spacing[axis], v.data(), z.data(),
                       g.data());
      }
      for (int q = 0; q < n[axis]; ++q) {
        float* out = first + q * step;
        const double* in = tile.data() + static_cast<std::size_t>(q) * kTile;
        for (int b = 0; b < count; ++b) out[b] = static_cast<float>(in[b]);
      }
    }
  };
  for (int k = lo[2]; k < hi[2]; ++k) tiled(1, row, k * slice);
  for (int j = 0; j < n[1]; ++j) tiled(2, slice, j * row);
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

DistanceField::DistanceField(const DistanceField& other, const VolumeData& data)
    : data_(data),
      labels_(other.labels_),
      is_member_(other.is_member_),
      band_(other.band_),
      reach_(other.reach_),
      revision_(data.revision()),
      structure_voxels_(other.structure_voxels_),
      bounds_(other.bounds_),
      region_(other.region_),
      values_(other.values_),
      mask_(other.mask_) {
  if (data.shape() != other.data_.shape() ||
      !data.voxel_size().isApprox(other.data_.voxel_size(), 1e-12)) {
    throw ArgumentError(
        "DistanceField: a copy must follow a volume of the same shape and voxel "
        "size as the original's");
  }
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
  const float inf = std::numeric_limits<float>::infinity();
  // Squared distance to the structure, over src; membership is where it is 0.
  std::vector<float> outside(total);
  std::array<int, 3> lo{n[0], n[1], n[2]}, hi{0, 0, 0};  // the members' box, src coordinates
  std::int64_t members = 0;
  std::size_t idx = 0;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i, ++idx) {
        const bool m = member(src.lo[0] + i, src.lo[1] + j, src.lo[2] + k);
        outside[idx] = m ? 0.0f : inf;
        if (!m) continue;
        ++members;
        const int c[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], c[a]);
          hi[a] = std::max(hi[a], c[a] + 1);
        }
      }
    }
  }
  const Eigen::Vector3d spacing = data_.voxel_size();
  if (members > 0) squared_distances(outside, n, spacing, lo, hi);
  // Squared distance to the nearest non-member, needed only at members. The nearest one to a
  // member is never beyond the members' box grown by one voxel: clamping any non-member's
  // coordinates to that box gives a voxel no farther away that is also not a member (it is
  // either the same voxel or outside the members' box). So the transform runs over that box only.
  std::array<int, 3> in_lo{}, in_n{};
  std::vector<float> inside;
  const bool any_other = members < static_cast<std::int64_t>(total);
  if (members > 0 && any_other) {
    for (int a = 0; a < 3; ++a) {
      in_lo[a] = std::max(lo[a] - 1, 0);
      in_n[a] = std::min(hi[a] + 1, n[a]) - in_lo[a];
    }
    inside.resize(static_cast<std::size_t>(in_n[0]) * in_n[1] * in_n[2]);
    std::size_t t = 0;
    for (int k = 0; k < in_n[2]; ++k) {
      for (int j = 0; j < in_n[1]; ++j) {
        const float* o =
            outside.data() + in_lo[0] +
            static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(in_lo[1] + j) +
                                              static_cast<std::size_t>(n[1]) * (in_lo[2] + k));
        for (int i = 0; i < in_n[0]; ++i) inside[t++] = o[i] == 0.0f ? inf : 0.0f;
      }
    }
    squared_distances(inside, in_n, spacing, {0, 0, 0}, in_n);
  }

  const int rn0 = region_.hi[0] - region_.lo[0];
  const int rn1 = region_.hi[1] - region_.lo[1];
  const float band = static_cast<float>(band_);
  for (int k = out.lo[2]; k < out.hi[2]; ++k) {
    for (int j = out.lo[1]; j < out.hi[1]; ++j) {
      for (int i = out.lo[0]; i < out.hi[0]; ++i) {
        const int a = i - src.lo[0], b = j - src.lo[1], c = k - src.lo[2];
        const std::size_t s = static_cast<std::size_t>(a) +
                              static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(b) +
                                                                static_cast<std::size_t>(n[1]) * c);
        const std::size_t r =
            static_cast<std::size_t>(i - region_.lo[0]) +
            static_cast<std::size_t>(rn0) * (static_cast<std::size_t>(j - region_.lo[1]) +
                                             static_cast<std::size_t>(rn1) * (k - region_.lo[2]));
        const bool m = outside[s] == 0.0f;
        double d = kInf;
        if (!m) {
          d = std::sqrt(static_cast<double>(outside[s]));
        } else if (any_other) {
          const std::size_t t = static_cast<std::size_t>(a - in_lo[0]) +
                                static_cast<std::size_t>(in_n[0]) *
                                    (static_cast<std::size_t>(b - in_lo[1]) +
                                     static_cast<std::size_t>(in_n[1]) * (c - in_lo[2]));
          d = -std::sqrt(static_cast<double>(inside[t]));
        }
        values_[r] = std::isfinite(d) ? static_cast<float>(std::clamp(d, -band_, band_))
                                      : (m ? -band : band);
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
  const int rn0 = region_.hi[0] - region_.lo[0];
  const int rn1 = region_.hi[1] - region_.lo[1];
  const bool inside = n[0] > 1 && n[1] > 1 && n[2] > 1 && lo[0] >= region_.lo[0] &&
                      lo[1] >= region_.lo[1] && lo[2] >= region_.lo[2] &&
                      lo[0] + 1 < region_.hi[0] && lo[1] + 1 < region_.hi[1] &&
                      lo[2] + 1 < region_.hi[2];
  if (inside) {
    // The common case, the eight corners stored: one index, fixed strides (as stored() reads).
    const std::size_t sj = static_cast<std::size_t>(rn0);
    const std::size_t sk = sj * static_cast<std::size_t>(rn1);
    const float* base = values_.data() + static_cast<std::size_t>(lo[0] - region_.lo[0]) +
                        sj * static_cast<std::size_t>(lo[1] - region_.lo[1]) +
                        sk * static_cast<std::size_t>(lo[2] - region_.lo[2]);
    const float band = static_cast<float>(band_);
    for (int dk = 0; dk < 2; ++dk) {
      for (int dj = 0; dj < 2; ++dj) {
        const float* row = base + dk * sk + dj * sj;
        for (int di = 0; di < 2; ++di) {
          const float f = row[di];
          v[dk][dj][di] = f >= band ? band_ : f <= -band ? -band_ : f;
        }
      }
    }
  } else {
    for (int dk = 0; dk < 2; ++dk) {
      for (int dj = 0; dj < 2; ++dj) {
        for (int di = 0; di < 2; ++di) {
          v[dk][dj][di] = stored(std::min(lo[0] + di, n[0] - 1), std::min(lo[1] + dj, n[1] - 1),
                                 std::min(lo[2] + dk, n[2] - 1));
        }
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
