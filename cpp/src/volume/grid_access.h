#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// Calls f with the label grid as uint8_t* or uint16_t*, by type, and returns what f returns.
template <typename Bytes, typename F>
auto visit_labels(LabelType type, Bytes* data, F&& f) {
  if (type == LabelType::kUInt8) {
    using T = std::conditional_t<std::is_const_v<Bytes>, const std::uint8_t, std::uint8_t>;
    return f(reinterpret_cast<T*>(data));
  }
  using T = std::conditional_t<std::is_const_v<Bytes>, const std::uint16_t, std::uint16_t>;
  return f(reinterpret_cast<T*>(data));
}

/// Trilinear reads of a uint8 field whose voxel (i, j, k) is centred at (i + 0.5, j + 0.5, k + 0.5)
/// in voxel units; outside the grid the field is 0 (what a GL texture with a zero border gives).
struct VolumeField {
  const std::uint8_t* data;
  std::array<int, 3> shape;

  int at(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= shape[0] || j >= shape[1] || k >= shape[2]) return 0;
    return data[static_cast<std::size_t>(i) +
                static_cast<std::size_t>(shape[0]) *
                    (static_cast<std::size_t>(j) + static_cast<std::size_t>(shape[1]) * k)];
  }

  /// 0..255, trilinear.
  double sample(const Eigen::Vector3d& u) const {
    const Eigen::Vector3d c = u - Eigen::Vector3d::Constant(0.5);
    const int i = static_cast<int>(std::floor(c.x())), j = static_cast<int>(std::floor(c.y())),
              k = static_cast<int>(std::floor(c.z()));
    const double fx = c.x() - i, fy = c.y() - j, fz = c.z() - k;
    const double c00 = at(i, j, k) * (1 - fx) + at(i + 1, j, k) * fx;
    const double c10 = at(i, j + 1, k) * (1 - fx) + at(i + 1, j + 1, k) * fx;
    const double c01 = at(i, j, k + 1) * (1 - fx) + at(i + 1, j, k + 1) * fx;
    const double c11 = at(i, j + 1, k + 1) * (1 - fx) + at(i + 1, j + 1, k + 1) * fx;
    return (c00 * (1 - fy) + c10 * fy) * (1 - fz) + (c01 * (1 - fy) + c11 * fy) * fz;
  }

  /// The gradient's direction from four samples at the corners (+-span each axis) of a
  /// tetrahedron around u (unnormalised).
  Eigen::Vector3d gradient(const Eigen::Vector3d& u, double span = 1.0) const {
    const double a0 = sample(u + span * Eigen::Vector3d(1, 1, 1));
    const double a1 = sample(u + span * Eigen::Vector3d(1, -1, -1));
    const double a2 = sample(u + span * Eigen::Vector3d(-1, 1, -1));
    const double a3 = sample(u + span * Eigen::Vector3d(-1, -1, 1));
    return Eigen::Vector3d(a0 + a1 - a2 - a3, a0 - a1 + a2 - a3, a0 - a1 - a2 + a3);
  }
};

/// The label of voxel (i, j, k) and its linear index (i fastest); 0 outside the grid.
template <typename T>
std::uint16_t label_in_grid(const T* labels, const std::array<int, 3>& shape, int i, int j, int k,
                            std::size_t* index) {
  if (i < 0 || j < 0 || k < 0 || i >= shape[0] || j >= shape[1] || k >= shape[2]) return 0;
  *index = static_cast<std::size_t>(i) +
           static_cast<std::size_t>(shape[0]) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(shape[1]) * k);
  return labels[*index];
}

/// The non-zero label with the largest trilinear weight among the 8 voxels around u (0 if none),
/// and, if asked, that voxel's linear index (-1 if none).
template <typename T>
std::uint16_t dominant_label(const T* labels, const std::array<int, 3>& shape,
                             const Eigen::Vector3d& u, std::int64_t* voxel = nullptr) {
  const Eigen::Vector3d c = u - Eigen::Vector3d::Constant(0.5);
  const int i0 = static_cast<int>(std::floor(c.x())), j0 = static_cast<int>(std::floor(c.y())),
            k0 = static_cast<int>(std::floor(c.z()));
  const double f[3] = {c.x() - i0, c.y() - j0, c.z() - k0};
  std::uint16_t best = 0;
  double best_w = -1;
  if (voxel != nullptr) *voxel = -1;
  for (int corner = 0; corner < 8; ++corner) {
    const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
    const int i = i0 + di, j = j0 + dj, k = k0 + dk;
    std::size_t index;
    const std::uint16_t l = label_in_grid(labels, shape, i, j, k, &index);
    if (l == 0) continue;
    const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
    // Strictly greater: ties go to the lowest corner index, as in the shader.
    if (w > best_w) {
      best_w = w;
      best = l;
      if (voxel != nullptr) *voxel = static_cast<std::int64_t>(index);
    }
  }
  return best;
}

/// The non-zero label of the solid voxel whose centre is nearest u, among the 6 x 6 x 6 voxels
/// within 2 of the 8 around u (0 if none), and, if asked, its linear index (-1 if none). Where
/// the smoothed surface rounds a concave corner over 8 empty voxels, the material that raised
/// the field there: as the shader's nearest_label, with ties to the first in k, j, i order.
template <typename T>
std::uint16_t nearest_label(const T* labels, const std::array<int, 3>& shape,
                            const Eigen::Vector3d& u, std::int64_t* voxel = nullptr) {
  const Eigen::Vector3d c = u - Eigen::Vector3d::Constant(0.5);
  const int i0 = static_cast<int>(std::floor(c.x())), j0 = static_cast<int>(std::floor(c.y())),
            k0 = static_cast<int>(std::floor(c.z()));
  std::uint16_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  if (voxel != nullptr) *voxel = -1;
  for (int k = k0 - 2; k <= k0 + 3; ++k) {
    for (int j = j0 - 2; j <= j0 + 3; ++j) {
      for (int i = i0 - 2; i <= i0 + 3; ++i) {
        std::size_t index;
        const std::uint16_t l = label_in_grid(labels, shape, i, j, k, &index);
        if (l == 0) continue;
        const double d = (Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) - u).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best = l;
          if (voxel != nullptr) *voxel = static_cast<std::int64_t>(index);
        }
      }
    }
  }
  return best;
}

}  // namespace ambfplus
