#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <thread>

#include "ambfplus/volume/volume_data.h"
#include "haptics/critical_distances.h"

namespace ambfplus {
namespace {

// The nearest centre of a voxel with this label, by looking at every voxel.
double brute_force(const VolumeData& v, const Eigen::Vector3d& p, std::uint16_t label) {
  double best = std::numeric_limits<double>::infinity();
  const auto& n = v.shape();
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (v.label(i, j, k) == label) best = std::min(best, (v.voxel_center(i, j, k) - p).norm());
      }
  return best;
}

// Points outside the structure, where the drill's burr is: the nearest voxel of a structure to
// such a point is on its boundary, which is all the class keeps.
// A slab of a critical label eaten away layer by layer exposes far more than kRebuildAfter
// voxels: queries are exact while the rebuild runs on its thread and after it took over.
TEST(CriticalDistances, ExactBeforeDuringAndAfterARebuild) {
  const LabelTable table({Label{1, "Bone", {200, 200, 200}, true, false},
                          Label{2, "Nerve", {250, 220, 0}, true, true}});
  VolumeData v({48, 48, 24}, Eigen::Vector3d(0.048, 0.048, 0.024), LabelType::kUInt8, table);
  v.set_region(VoxelBox{{0, 0, 0}, {48, 48, 24}}, 1);
  v.set_region(VoxelBox{{4, 4, 4}, {44, 44, 20}}, 2);
  CriticalDistances distances(v, {2});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-0.03, 0.03);
  auto check = [&](const char* when) {
    for (int q = 0; q < 12;) {
      const Eigen::Vector3d p(at(rng), at(rng), at(rng));
      const Eigen::Vector3d u = v.to_voxel_units(p);
      const bool inside = (u.array() >= 0).all() && u.x() < 48 && u.y() < 48 && u.z() < 24 &&
                          v.label(int(u.x()), int(u.y()), int(u.z())) == 2;
      if (inside) continue;
      ++q;
      ASSERT_NEAR(distances.distance(p, 2), brute_force(v, p, 2), 1e-12) << when;
    }
  };
  check("before removal");
  // Peel the nerve from the top, voxel by voxel, as a drill would.
  for (int k = 19; k >= 16; --k) {
    std::vector<std::array<int, 3>> layer;
    for (int j = 4; j < 44; ++j)
      for (int i = 4; i < 44; ++i) layer.push_back({i, j, k});
    const std::vector<std::uint16_t> old = v.remove_voxels(layer);
    for (std::size_t n = 0; n < layer.size(); ++n) {
      if (old[n] == 2) distances.removed(layer[n], 2);
    }
  }
  check("while rebuilding");
  for (int wait = 0; wait < 200 && distances.rebuilds() == 0; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    (void)distances.distance(Eigen::Vector3d::Zero(), 2);  // takes a finished tree
  }
  EXPECT_GE(distances.rebuilds(), 1);
  check("after the rebuild");
}

}  // namespace
}  // namespace ambfplus
