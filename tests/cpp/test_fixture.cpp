#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ambfplus/volume/structure_distances.h"
#include "ambfplus/volume/volume_data.h"

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

// The drill's distances: exact at voxel centres within the band, a lower bound of at least the
// band beyond it, and still so while the structure is cut away layer by layer, to nothing.
TEST(StructureDistances, ExactInTheBandALowerBoundBeyondAndFollowingCuts) {
  const LabelTable table({Label{1, "Bone", {200, 200, 200}, true, false},
                          Label{2, "Nerve", {250, 220, 0}, true, true}});
  VolumeData v({40, 40, 24}, Eigen::Vector3d(0.040, 0.040, 0.024), LabelType::kUInt8, table);
  v.set_region(VoxelBox{{0, 0, 0}, {40, 40, 24}}, 1);
  v.set_region(VoxelBox{{14, 16, 8}, {22, 20, 12}}, 2);
  const double band = 0.006;
  StructureDistances distances(v);
  distances.track(2, band);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> ix(0, 39), kz(0, 23);
  auto check = [&](const char* when) -> int {
    int exact = 0, beyond = 0;
    for (int q = 0; q < 300; ++q) {
      const int i = ix(rng), j = ix(rng), k = kz(rng);
      if (v.label(i, j, k) == 2) continue;
      const Eigen::Vector3d p = v.voxel_center(i, j, k);
      const double truth = brute_force(v, p, 2);
      const double got = distances.distance(2, p);
      if (std::isinf(truth)) {
        EXPECT_TRUE(std::isinf(got)) << when;
      } else if (truth < band - 1e-9) {
        EXPECT_NEAR(got, truth, 1e-6) << when;
        ++exact;
      } else {
        EXPECT_GE(got, band - 1e-9) << when;
        EXPECT_LE(got, truth + 1e-9) << when;
        ++beyond;
      }
    }
    return exact + beyond;
  };
  EXPECT_GT(check("before any cut"), 100);
  for (int k = 11; k >= 8; --k) {
    std::vector<std::array<int, 3>> layer;
    for (int j = 16; j < 20; ++j)
      for (int i = 14; i < 22; ++i) layer.push_back({i, j, k});
    const std::int64_t before = v.revision();
    const std::vector<std::uint16_t> old = v.remove_voxels(layer);
    distances.removed(before, layer, old);
    for (int t = 0; t <= StructureDistances::kFollowTicks; ++t) distances.tick();
    check("after a cut");
  }
  EXPECT_TRUE(std::isinf(distances.distance(2, Eigen::Vector3d::Zero())));
  EXPECT_EQ(distances.rebuilds(), 4);
}

// Until the rebuilt field is due, the old one answers: a lower bound after a cut, the same in
// every run (the tick decides, not the threads).
TEST(StructureDistances, ARebuiltFieldIsTakenAtItsTick) {
  const LabelTable table({Label{1, "Bone", {200, 200, 200}, true, false},
                          Label{2, "Nerve", {250, 220, 0}, true, true}});
  VolumeData v({20, 20, 20}, Eigen::Vector3d(0.02, 0.02, 0.02), LabelType::kUInt8, table);
  v.set_region(VoxelBox{{0, 0, 0}, {20, 20, 20}}, 1);
  v.set_region(VoxelBox{{8, 8, 2}, {12, 12, 6}}, 2);
  StructureDistances distances(v);
  distances.track(2, 0.008);
  const Eigen::Vector3d p = v.voxel_center(10, 10, 9);
  const double d0 = distances.distance(2, p);
  std::vector<std::array<int, 3>> top;
  for (int j = 8; j < 12; ++j)
    for (int i = 8; i < 12; ++i) top.push_back({i, j, 5});
  const std::int64_t before = v.revision();
  const std::vector<std::uint16_t> old = v.remove_voxels(top);
  distances.removed(before, top, old);
  for (int t = 0; t < StructureDistances::kFollowTicks; ++t) {
    distances.tick();
    ASSERT_EQ(distances.distance(2, p), d0) << "tick " << t;
  }
  distances.tick();
  EXPECT_NEAR(distances.distance(2, p), brute_force(v, p, 2), 1e-6);
  EXPECT_GT(distances.distance(2, p), d0 + 0.0009);
}

// Cutting bone only does not touch a structure's field (its box is skipped, not scanned).
TEST(StructureDistances, CutsOfOtherLabelsLeaveTheFieldAsItWas) {
  const LabelTable table({Label{1, "Bone", {200, 200, 200}, true, false},
                          Label{2, "Nerve", {250, 220, 0}, true, true}});
  VolumeData v({20, 20, 20}, Eigen::Vector3d(0.02, 0.02, 0.02), LabelType::kUInt8, table);
  v.set_region(VoxelBox{{0, 0, 0}, {20, 20, 20}}, 1);
  v.set_region(VoxelBox{{8, 8, 2}, {12, 12, 4}}, 2);
  StructureDistances distances(v);
  distances.track(2, 0.005);
  const Eigen::Vector3d p = v.voxel_center(10, 10, 9);
  const double d0 = distances.distance(2, p);
  const std::int64_t before = v.revision();
  const std::vector<std::array<int, 3>> far{{10, 10, 15}, {10, 10, 16}};
  const std::vector<std::uint16_t> old = v.remove_voxels(far);
  distances.removed(before, far, old);
  for (int t = 0; t <= 2 * StructureDistances::kFollowTicks; ++t) distances.tick();
  EXPECT_EQ(distances.distance(2, p), d0);
  EXPECT_DOUBLE_EQ(d0, brute_force(v, p, 2));
  EXPECT_EQ(distances.rebuilds(), 0);
  // An edit by someone else in the structure's neighbourhood is noticed (and rebuilt for).
  v.set_region(VoxelBox{{10, 10, 6}, {11, 11, 7}}, 2);
  for (int t = 0; t <= StructureDistances::kFollowTicks + 1; ++t) distances.tick();
  EXPECT_EQ(distances.rebuilds(), 1);
  EXPECT_NEAR(distances.distance(2, p), brute_force(v, p, 2), 1e-6);
}

}  // namespace
}  // namespace ambfplus
