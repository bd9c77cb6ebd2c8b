#pragma once

#include <Eigen/Core>

#include "ambfplus/export.h"

namespace ambfplus::capture {

/// The organised point cloud of a depth image: for pixel (row r, column c) with depth z > 0,
/// z * K^-1 (c + 0.5, r + 0.5, 1) in the camera frame (the engine's pixel-centre convention),
/// (0, 0, 0) where z is 0. depth is height x width, points height x width x 3, both tightly
/// packed.
AMBFPLUS_API void points_from_depth(const float* depth, const Eigen::Matrix3d& intrinsics,
                                    int width, int height, float* points);

}  // namespace ambfplus::capture
