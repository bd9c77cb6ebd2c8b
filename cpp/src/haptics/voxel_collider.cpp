#include "ambfplus/haptics/voxel_collider.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "volume/grid_access.h"

namespace ambfplus {
namespace {

constexpr int B = 8;  // brick edge, voxels: 512 bits per brick

// An AVX2 clone chosen at load time (an ifunc). Not under ThreadSanitizer: the loader runs the
// clone's resolver before the sanitizer's runtime is set up, and the instrumented resolver then
// crashes the process before main.
#if defined(__SANITIZE_THREAD__)
#define AMBFPLUS_AVX2_CLONES
#else
#define AMBFPLUS_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#endif

// Entry fraction (0..1) of a sphere of radius R swept from a along unit d for `length` into each
// voxel sphere centred at (x, y, z)[i], 2 where it does not enter; as VoxelCollider::enter().
AMBFPLUS_AVX2_CLONES void entry_fractions(const double* x, const double* y, const double* z,
                                          std::size_t n, double ax, double ay, double az, double dx,
                                          double dy, double dz, double length, double R,
                                          double* out) {
  const double R2 = R * R, inv_length = length > 0 ? 1.0 / length : 0.0;
  // Still: touching blocks nothing. (One simple select per condition, so the loop has no branches
  // and vectorises.)
  const double blocked_touch = length <= 0 ? 2.0 : 0.0;
  const double moves = length <= 0 ? 0.0 : 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double mx = ax - x[i], my = ay - y[i], mz = az - z[i];
    const double c2 = mx * mx + my * my + mz * mz - R2;
    const double bd = mx * dx + my * dy + mz * dz;
    const double disc = bd * bd - c2;
    const double enter_at = (-bd - std::sqrt(std::max(disc, 0.0))) * inv_length;
    double moving = disc >= 0.0 ? enter_at : 2.0;
    moving = moving <= 1.0 ? moving : 2.0;
    moving = bd < 0.0 ? moving : 2.0;
    moving = moves > 0.0 ? moving : 2.0;
    const double touching = bd < 0.0 ? blocked_touch : 2.0;
    out[i] = c2 <= 0.0 ? touching : moving;
  }
}

}  // namespace

VoxelCollider::VoxelCollider(std::shared_ptr<VolumeData> data)
    : data_(std::move(data)), shape_(data_->shape()), voxel_size_(data_->voxel_size()) {
  for (int a = 0; a < 3; ++a) bricks_[a] = (shape_[a] + B - 1) / B;
  rho_ = 0.5 * std::cbrt(voxel_size_.prod());
  const std::size_t n = std::size_t(bricks_[0]) * bricks_[1] * bricks_[2];
  surface_.assign(n * 8, 0);
  surface_count_.assign(n, 0);
  rebuild(VoxelBox{{0, 0, 0}, shape_});
  revision_ = data_->revision();
}

std::size_t VoxelCollider::brick_index(int bi, int bj, int bk) const {
  return static_cast<std::size_t>(bi) +
         std::size_t(bricks_[0]) * (std::size_t(bj) + std::size_t(bricks_[1]) * bk);
}

bool VoxelCollider::surface(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= shape_[0] || j >= shape_[1] || k >= shape_[2]) return false;
  const std::size_t b = brick_index(i / B, j / B, k / B);
  return (surface_[b * 8 + k % B] >> ((j % B) * B + i % B)) & 1u;
}

void VoxelCollider::refresh_surface(int i, int j, int k) {
  if (i < 0 || j < 0 || k < 0 || i >= shape_[0] || j >= shape_[1] || k >= shape_[2]) return;
  const bool is =
      solid(i, j, k) && (!solid(i - 1, j, k) || !solid(i + 1, j, k) || !solid(i, j - 1, k) ||
                         !solid(i, j + 1, k) || !solid(i, j, k - 1) || !solid(i, j, k + 1));
  const std::size_t b = brick_index(i / B, j / B, k / B);
  std::uint64_t& word = surface_[b * 8 + k % B];
  const std::uint64_t bit = std::uint64_t{1} << ((j % B) * B + i % B);
  const bool was = word & bit;
  if (is == was) return;
  word ^= bit;
  surface_count_[b] = static_cast<std::uint16_t>(surface_count_[b] + (is ? 1 : -1));
}

void VoxelCollider::rebuild(const VoxelBox& box) {
  const VoxelBox r = box.grown(1).clipped(shape_);
  for (int k = r.lo[2]; k < r.hi[2]; ++k)
    for (int j = r.lo[1]; j < r.hi[1]; ++j)
      for (int i = r.lo[0]; i < r.hi[0]; ++i) refresh_surface(i, j, k);
}

void VoxelCollider::sync() {
  VoxelBox box;
  if (data_->dirty_since(revision_, &box) && !box.empty()) {
    rebuild(box);
    ++outside_edits_;
  }
  revision_ = data_->revision();
}

double VoxelCollider::enter(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double length,
                            const Eigen::Vector3d& c, double R) {
  const Eigen::Vector3d m = a - c;
  const double c2 = m.squaredNorm() - R * R;
  const double b = m.dot(d);
  // Already touching: blocked only when moving further in, so a proxy resting on a surface can
  // slide along it and leave it.
  if (c2 <= 0) return length <= 0 || b < 0 ? 0.0 : 2.0;
  if (length <= 0) return 2.0;
  if (b >= 0) return 2.0;  // moving away
  const double disc = b * b - c2;
  if (disc < 0) return 2.0;
  const double t = -b - std::sqrt(disc);
  return t <= length ? t / length : 2.0;
}

template <typename F>
void VoxelCollider::for_surface_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double R,
                                     F&& f) const {
  const Eigen::Vector3d delta = b - a;
  const double length = delta.norm();
  const Eigen::Vector3d d = length > 0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::Zero();
  // Voxel index range of the capsule's box.
  const Eigen::Vector3d lo = data_->to_voxel_units(a.cwiseMin(b) - Eigen::Vector3d::Constant(R));
  const Eigen::Vector3d hi = data_->to_voxel_units(a.cwiseMax(b) + Eigen::Vector3d::Constant(R));
  std::array<int, 3> vlo, vhi;
  for (int ax = 0; ax < 3; ++ax) {
    vlo[ax] = std::max(0, static_cast<int>(std::floor(lo[ax] - 0.5)));
    vhi[ax] = std::min(shape_[ax] - 1, static_cast<int>(std::ceil(hi[ax] - 0.5)));
    if (vlo[ax] > vhi[ax]) return;
  }
  const Eigen::Vector3d half = data_->dimensions() / 2;
  // A brick can hold a voxel within R of the segment only if its centre is within R plus half
  // its diagonal.
  const double brick_reach = 0.5 * B * voxel_size_.norm() + R;
  for (int bk = vlo[2] / B; bk <= vhi[2] / B; ++bk) {
    for (int bj = vlo[1] / B; bj <= vhi[1] / B; ++bj) {
      for (int bi = vlo[0] / B; bi <= vhi[0] / B; ++bi) {
        const std::size_t bidx = brick_index(bi, bj, bk);
        if (surface_count_[bidx] == 0) continue;
        const Eigen::Vector3d centre =
            Eigen::Vector3d((bi + 0.5) * B, (bj + 0.5) * B, (bk + 0.5) * B)
                .cwiseProduct(voxel_size_) -
            half;
        const double s = length > 0 ? std::clamp((centre - a).dot(d), 0.0, length) : 0.0;
        if ((a + s * d - centre).norm() > brick_reach) continue;
        for (int z = 0; z < B; ++z) {
          const int k = bk * B + z;
          if (k < vlo[2] || k > vhi[2]) continue;
          std::uint64_t word = surface_[bidx * 8 + z];
          while (word) {
            const int bit = __builtin_ctzll(word);
            word &= word - 1;
            const int i = bi * B + bit % B, j = bj * B + bit / B;
            if (i < vlo[0] || i > vhi[0] || j < vlo[1] || j > vhi[1]) continue;
            f(i, j, k,
              Eigen::Vector3d(Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(voxel_size_) -
                              half));
          }
        }
      }
    }
  }
}

SweepHit VoxelCollider::sweep(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) const {
  SweepHit best;
  const double R = r + rho_;
  const Eigen::Vector3d delta = b - a;
  const double length = delta.norm();
  const Eigen::Vector3d d = length > 0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::Zero();
  for_surface_near(a, b, R, [&](int i, int j, int k, const Eigen::Vector3d& c) {
    ++tested_;
    const double t = enter(a, d, length, c, R);
    // The earliest contact; among equal ones the lowest voxel index, whatever the scan order.
    if (t <= 1.0 &&
        (!best.hit || t < best.t || (t == best.t && std::array<int, 3>{i, j, k} < best.voxel))) {
      best.hit = true;
      best.t = t;
      best.voxel = {i, j, k};
      best.voxel_center = c;
    }
  });
  return best;
}

SurfacePatch VoxelCollider::gather(const Eigen::Vector3d& c, double radius) const {
  SurfacePatch patch;
  gather(c, radius, patch);
  return patch;
}

void VoxelCollider::gather(const Eigen::Vector3d& c, double radius, SurfacePatch& patch) const {
  patch.x.clear();
  patch.y.clear();
  patch.z.clear();
  patch.voxels.clear();
  patch.centre = c;
  patch.radius = radius;
  const Eigen::Vector3d lo = data_->to_voxel_units(c - Eigen::Vector3d::Constant(radius));
  const Eigen::Vector3d hi = data_->to_voxel_units(c + Eigen::Vector3d::Constant(radius));
  std::array<int, 3> vlo, vhi;
  for (int ax = 0; ax < 3; ++ax) {
    vlo[ax] = std::max(0, static_cast<int>(std::floor(lo[ax] - 0.5)));
    vhi[ax] = std::min(shape_[ax] - 1, static_cast<int>(std::ceil(hi[ax] - 0.5)));
    if (vlo[ax] > vhi[ax]) return;
  }
  const double sx = voxel_size_.x(), sy = voxel_size_.y(), sz = voxel_size_.z();
  const Eigen::Vector3d half = data_->dimensions() / 2;
  const double ox = 0.5 * sx - half.x() - c.x(), oy = 0.5 * sy - half.y() - c.y(),
               oz = 0.5 * sz - half.z() - c.z();  // voxel (i, j, k) is at (i s + o) from c
  const double r2 = radius * radius;
  const double brick_half = 0.5 * B * voxel_size_.norm();
  for (int bk = vlo[2] / B; bk <= vhi[2] / B; ++bk) {
    for (int bj = vlo[1] / B; bj <= vhi[1] / B; ++bj) {
      for (int bi = vlo[0] / B; bi <= vhi[0] / B; ++bi) {
        const std::size_t bidx = brick_index(bi, bj, bk);
        if (surface_count_[bidx] == 0) continue;
        const double cx = (bi * B + 0.5 * B - 0.5) * sx + ox,
                     cy = (bj * B + 0.5 * B - 0.5) * sy + oy,
                     cz = (bk * B + 0.5 * B - 0.5) * sz + oz;
        const double reach = radius + brick_half;
        if (cx * cx + cy * cy + cz * cz > reach * reach) continue;
        for (int z = 0; z < B; ++z) {
          const int k = bk * B + z;
          std::uint64_t word = surface_[bidx * 8 + z];
          const double dz = k * sz + oz;
          while (word) {
            const int bit = __builtin_ctzll(word);
            word &= word - 1;
            const int i = bi * B + bit % B, j = bj * B + bit / B;
            const double dx = i * sx + ox, dy = j * sy + oy;
            if (dx * dx + dy * dy + dz * dz > r2) continue;
            patch.x.push_back(dx + c.x());
            patch.y.push_back(dy + c.y());
            patch.z.push_back(dz + c.z());
            patch.voxels.push_back({i, j, k});
          }
        }
      }
    }
  }
}

SweepHit VoxelCollider::sweep(const SurfacePatch& patch, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, double r) const {
  const double R = r + rho_;
  if (!patch.covers(a, b, R)) return sweep(a, b, r);
  SweepHit best;
  const Eigen::Vector3d delta = b - a;
  const double length = delta.norm();
  const Eigen::Vector3d d = length > 0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::Zero();
  const std::size_t n = patch.voxels.size();
  tested_ += static_cast<std::int64_t>(n);
  // The entry fraction of every voxel, without branches (the loop vectorises), then the least.
  // Same rules as enter(): touching blocks only inward motion; missing gives 2.
  // Every voxel's entry fraction in one branch-free pass (it vectorises, with AVX2 where the CPU
  // has it), then the least; the same rules as enter().
  thread_local std::vector<double> t;
  t.resize(n);
  entry_fractions(patch.x.data(), patch.y.data(), patch.z.data(), n, a.x(), a.y(), a.z(), d.x(),
                  d.y(), d.z(), length, R, t.data());
  std::size_t first = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (t[i] > 1.0) continue;
    if (first == n || t[i] < t[first] ||
        (t[i] == t[first] && patch.voxels[i] < patch.voxels[first])) {
      first = i;
    }
  }
  if (first < n) {
    best.hit = true;
    best.t = t[first];
    best.voxel = patch.voxels[first];
    best.voxel_center = Eigen::Vector3d(patch.x[first], patch.y[first], patch.z[first]);
  }
  return best;
}

std::vector<std::array<int, 3>> VoxelCollider::surface_within(const Eigen::Vector3d& c,
                                                              double radius) const {
  std::vector<std::array<int, 3>> out;
  const double r2 = radius * radius;
  for_surface_near(c, c, radius, [&](int i, int j, int k, const Eigen::Vector3d& v) {
    if ((v - c).squaredNorm() <= r2) out.push_back({i, j, k});
  });
  return out;
}

SweepHit VoxelCollider::sweep_full_cube(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        double r) const {
  SweepHit best;
  const double R = r + rho_;
  const Eigen::Vector3d delta = b - a;
  const double length = delta.norm();
  const Eigen::Vector3d d = length > 0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::Zero();
  const double step = voxel_size_.minCoeff();
  const int steps = std::max(1, static_cast<int>(std::ceil(length / step)));
  const std::array<int, 3> reach = {static_cast<int>(std::ceil(R / voxel_size_[0])) + 1,
                                    static_cast<int>(std::ceil(R / voxel_size_[1])) + 1,
                                    static_cast<int>(std::ceil(R / voxel_size_[2])) + 1};
  const Eigen::Vector3d half = data_->dimensions() / 2;
  // March until a step finds contacts; the earliest contact over the whole segment wins.
  for (int s = 0; s <= steps && !best.hit; ++s) {
    const Eigen::Vector3d p = a + d * std::min(length, s * step);
    const Eigen::Vector3d u = data_->to_voxel_units(p);
    const int ci = static_cast<int>(std::floor(u.x())), cj = static_cast<int>(std::floor(u.y())),
              ck = static_cast<int>(std::floor(u.z()));
    for (int k = std::max(0, ck - reach[2]); k <= std::min(shape_[2] - 1, ck + reach[2]); ++k)
      for (int j = std::max(0, cj - reach[1]); j <= std::min(shape_[1] - 1, cj + reach[1]); ++j)
        for (int i = std::max(0, ci - reach[0]); i <= std::min(shape_[0] - 1, ci + reach[0]); ++i) {
          ++tested_;
          if (data_->label(i, j, k) == 0) continue;
          const Eigen::Vector3d c =
              Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(voxel_size_) - half;
          if ((p - c).norm() > R + step) continue;
          const double t = enter(a, d, length, c, R);
          if (t <= 1.0 && (!best.hit || t < best.t ||
                           (t == best.t && std::array<int, 3>{i, j, k} < best.voxel))) {
            best.hit = true;
            best.t = t;
            best.voxel = {i, j, k};
            best.voxel_center = c;
          }
        }
  }
  return best;
}

Eigen::Vector3d VoxelCollider::normal(const Eigen::Vector3d& p, double radius) const {
  // The first moment of the occupancy in a ball around p points into the solid; its opposite is
  // the gradient of the occupancy smoothed by a kernel over that ball.
  const Eigen::Vector3d u = data_->to_voxel_units(p);
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(radius).cwiseQuotient(voxel_size_);
  const Eigen::Vector3d half = data_->dimensions() / 2;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  const double r2 = radius * radius;
  for (int k = std::max(0, int(std::floor(u.z() - reach.z())));
       k <= std::min(shape_[2] - 1, int(std::floor(u.z() + reach.z()))); ++k)
    for (int j = std::max(0, int(std::floor(u.y() - reach.y())));
         j <= std::min(shape_[1] - 1, int(std::floor(u.y() + reach.y()))); ++j)
      for (int i = std::max(0, int(std::floor(u.x() - reach.x())));
           i <= std::min(shape_[0] - 1, int(std::floor(u.x() + reach.x()))); ++i) {
        if (data_->label(i, j, k) == 0) continue;
        const Eigen::Vector3d c =
            Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(voxel_size_) - half;
        const Eigen::Vector3d v = c - p;
        const double q = v.squaredNorm() / r2;
        // A weight that falls smoothly to zero at the ball's edge, so voxels entering or leaving
        // the ball do not jerk the normal.
        if (q < 1.0) moment += v * ((1.0 - q) * (1.0 - q));
      }
  const double m = moment.norm();
  return m > 0 ? Eigen::Vector3d(-moment / m) : Eigen::Vector3d::Zero();
}

std::vector<std::array<int, 3>> VoxelCollider::solid_within(const Eigen::Vector3d& c,
                                                            double radius) const {
  std::vector<std::pair<double, std::array<int, 3>>> found;
  const Eigen::Vector3d u = data_->to_voxel_units(c);
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(radius).cwiseQuotient(voxel_size_);
  const Eigen::Vector3d half = data_->dimensions() / 2;
  const double r2 = radius * radius;
  for (int k = std::max(0, int(std::floor(u.z() - reach.z() - 0.5)));
       k <= std::min(shape_[2] - 1, int(std::ceil(u.z() + reach.z()))); ++k)
    for (int j = std::max(0, int(std::floor(u.y() - reach.y() - 0.5)));
         j <= std::min(shape_[1] - 1, int(std::ceil(u.y() + reach.y()))); ++j)
      for (int i = std::max(0, int(std::floor(u.x() - reach.x() - 0.5)));
           i <= std::min(shape_[0] - 1, int(std::ceil(u.x() + reach.x()))); ++i) {
        if (data_->label(i, j, k) == 0) continue;
        const Eigen::Vector3d v =
            Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(voxel_size_) - half;
        const double d2 = (v - c).squaredNorm();
        if (d2 <= r2) found.push_back({d2, {i, j, k}});
      }
  // Nearest first; ties by index so the order never depends on anything else.
  std::sort(found.begin(), found.end());
  std::vector<std::array<int, 3>> out;
  out.reserve(found.size());
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

std::vector<std::uint16_t> VoxelCollider::remove(const std::vector<std::array<int, 3>>& voxels) {
  sync();
  std::vector<std::uint16_t> old = data_->remove_voxels(voxels);
  for (const auto& v : voxels) {
    refresh_surface(v[0], v[1], v[2]);
    refresh_surface(v[0] - 1, v[1], v[2]);
    refresh_surface(v[0] + 1, v[1], v[2]);
    refresh_surface(v[0], v[1] - 1, v[2]);
    refresh_surface(v[0], v[1] + 1, v[2]);
    refresh_surface(v[0], v[1], v[2] - 1);
    refresh_surface(v[0], v[1], v[2] + 1);
  }
  revision_ = data_->revision();
  return old;
}

}  // namespace ambfplus
