#include "ambfplus/capture/points.h"

namespace ambfplus::capture {

void points_from_depth(const float* depth, const Eigen::Matrix3d& k, int width, int height,
                       float* points) {
  const double fx = k(0, 0), fy = k(1, 1), cx = k(0, 2), cy = k(1, 2);
  for (int r = 0; r < height; ++r) {
    const double y = (static_cast<double>(r) + 0.5 - cy) / fy;
    for (int c = 0; c < width; ++c, ++depth, points += 3) {
      const double z = *depth;
      points[0] = static_cast<float>((static_cast<double>(c) + 0.5 - cx) / fx * z);
      points[1] = static_cast<float>(y * z);
      points[2] = static_cast<float>(z);
    }
  }
}

}  // namespace ambfplus::capture
