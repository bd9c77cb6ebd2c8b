#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ambfplus/errors.h"
#include "ambfplus/volume/distance_field.h"
#include "ambfplus/volume/structure_distances.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {
namespace {

LabelTable anatomy() {
  return LabelTable({Label{1, "Bone", {200, 200, 200}, true, false},
                     Label{2, "Facial nerve", {250, 220, 0}, true, true},
                     Label{3, "Chorda", {250, 120, 0}, true, true}});
}

// A small anisotropic volume: bone everywhere, a few nerve blobs of labels 2 and 3.
void fill(VolumeData& v, unsigned seed) {
  const auto& n = v.shape();
  v.set_region(VoxelBox{{0, 0, 0}, {n[0], n[1], n[2]}}, 1);
  std::mt19937 rng(seed);
  for (int blob = 0; blob < 4; ++blob) {
    std::array<int, 3> lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::uniform_int_distribution<int>(0, n[a] - 4)(rng);
      hi[a] = lo[a] + std::uniform_int_distribution<int>(1, 4)(rng);
    }
    v.set_region(VoxelBox{lo, hi}, static_cast<std::uint16_t>(2 + blob % 2));
  }
}

// Brute force: the signed distance between voxel centres, clamped to the band.
double brute(const VolumeData& v, int i, int j, int k, double band) {
  const auto& n = v.shape();
  const auto in = [&](int a, int b, int c) {
    const auto l = v.label(a, b, c);
    return l == 2 || l == 3;
  };
  const bool inside = in(i, j, k);
  const Eigen::Vector3d p = v.voxel_center(i, j, k);
  double best = std::numeric_limits<double>::infinity();
  for (int c = 0; c < n[2]; ++c)
    for (int b = 0; b < n[1]; ++b)
      for (int a = 0; a < n[0]; ++a)
        if (in(a, b, c) != inside) best = std::min(best, (v.voxel_center(a, b, c) - p).norm());
  return std::clamp(inside ? -best : best, -band, band);
}

TEST(DistanceField, EqualsBruteForceOnAnisotropicVoxels) {
  VolumeData v({21, 15, 13}, Eigen::Vector3d(0.0042, 0.0045, 0.0026), LabelType::kUInt8, anatomy());
  fill(v, 7);
  const double band = 0.0015;
  DistanceField field(v, {2, 3}, band);
  const auto& n = v.shape();
  int inside = 0, clamped = 0, between = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const double want = brute(v, i, j, k, band);
        ASSERT_NEAR(field.at(i, j, k), want, 1e-9) << i << " " << j << " " << k;
        inside += want < 0;
        clamped += want >= band;
        between += want > 0 && want < band;
      }
  // The volume exercises every case: inside, within the band, beyond it.
  EXPECT_GT(inside, 0);
  EXPECT_GT(clamped, 0);
  EXPECT_GT(between, 0);
}

TEST(DistanceField, UpdatedFieldEqualsAFreshBuild) {
  VolumeData v({40, 36, 30}, Eigen::Vector3d(0.008, 0.0072, 0.009), LabelType::kUInt8, anatomy());
  fill(v, 11);
  v.commit();
  DistanceField field(v, {2, 3}, 0.001);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> where(-0.0035, 0.0035);
  std::int64_t recomputed = 0;
  for (int round = 0; round < 12; ++round) {
    // Drilling (through nerve and bone alike), a structure grown by an edit, and a reset.
    if (round == 5) {
      v.set_region(VoxelBox{{30, 2, 3}, {33, 5, 6}}, 3);
    } else if (round == 9) {
      v.reset();
    } else {
      v.remove_sphere(Eigen::Vector3d(where(rng), where(rng), where(rng)), 0.0012, false);
    }
    recomputed += field.update();
    const DistanceField fresh(v, {2, 3}, 0.001);
    EXPECT_EQ(field.structure_voxels(), fresh.structure_voxels()) << round;
    const auto a = field.values(), b = fresh.values();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t s = 0; s < a.size(); ++s) ASSERT_NEAR(a[s], b[s], 1e-9) << round << " " << s;
  }
  EXPECT_GT(recomputed, 0);
  EXPECT_EQ(field.revision(), v.revision());
}

TEST(DistanceField, EditsThatLeaveTheStructureCostNothing) {
  VolumeData v({24, 24, 24}, Eigen::Vector3d(0.006, 0.006, 0.006), LabelType::kUInt8, anatomy());
  v.set_region(VoxelBox{{0, 0, 0}, {24, 24, 24}}, 1);
  v.set_region(VoxelBox{{2, 2, 2}, {4, 4, 4}}, 2);
  DistanceField field(v, {2}, 0.002);
  // Bone far from the nerve: nothing of the structure changes.
  v.remove_sphere(Eigen::Vector3d(0.002, 0.002, 0.002), 0.0008, false);
  EXPECT_EQ(field.update(), 0);
  EXPECT_EQ(field.revision(), v.revision());
  EXPECT_EQ(field.structure_voxels(), 8);
}

TEST(DistanceField, SamplesInterpolateAndPointAwayFromTheStructure) {
  VolumeData v({31, 31, 31}, Eigen::Vector3d(0.0031, 0.0031, 0.0031), LabelType::kUInt8, anatomy());
  v.set_region(VoxelBox{{15, 15, 15}, {16, 16, 16}}, 2);
  DistanceField field(v, {2}, 0.001);
  // At voxel centres the sample is the stored value.
  for (auto c : {std::array<int, 3>{15, 15, 15}, {18, 15, 15}, {17, 19, 14}}) {
    EXPECT_NEAR(field.sample(v.voxel_center(c[0], c[1], c[2])).distance, field.at(c[0], c[1], c[2]),
                1e-12);
  }
  // Near the point structure the field is a cone: the gradient points away from it with a
  // length close to one, and the distance grows along it.
  const Eigen::Vector3d centre = v.voxel_center(15, 15, 15);
  for (const Eigen::Vector3d& dir :
       {Eigen::Vector3d(1, 0.3, -0.2), Eigen::Vector3d(-0.4, 1, 0.5)}) {
    const Eigen::Vector3d p = centre + 0.00043 * dir.normalized();
    const DistanceSample s = field.sample(p);
    EXPECT_NEAR(s.distance, 0.00043, 0.0001);
    EXPECT_GT(s.gradient.normalized().dot(dir.normalized()), 0.9);
    EXPECT_NEAR(s.gradient.norm(), 1.0, 0.25);
  }
  // Far away the field is clamped to the band, with no gradient.
  const DistanceSample far = field.sample(v.voxel_center(2, 2, 2));
  EXPECT_DOUBLE_EQ(far.distance, 0.001);
  EXPECT_EQ(far.gradient, Eigen::Vector3d::Zero());
}

TEST(DistanceField, RefusesBadArguments) {
  VolumeData v({4, 4, 4}, Eigen::Vector3d(0.004, 0.004, 0.004), LabelType::kUInt8, anatomy());
  EXPECT_THROW(DistanceField(v, {}, 0.001), ArgumentError);
  EXPECT_THROW(DistanceField(v, {0}, 0.001), ArgumentError);
  EXPECT_THROW(DistanceField(v, {2}, 0.0), ArgumentError);
  EXPECT_THROW(DistanceField(v, {2}, std::nan("")), ArgumentError);
  const DistanceField empty(v, {2}, 0.001);
  EXPECT_EQ(empty.structure_voxels(), 0);
  EXPECT_DOUBLE_EQ(empty.at(1, 2, 3), 0.001);
  EXPECT_THROW(empty.at(4, 0, 0), OutOfRange);
}

// The fields a drill reads follow its cuts: after kFollowTicks ticks the structure's distance
// equals a fresh field's of the edited volume wherever that is within the band, whether the
// successor was a local update (cuts told through removed(), or seen as another's edit) or a new
// build (the structure painted beyond its neighbourhood).
TEST(StructureDistances, FollowCutsAsAFreshFieldWould) {
  VolumeData v({40, 36, 30}, Eigen::Vector3d(0.008, 0.0072, 0.009), LabelType::kUInt8, anatomy());
  v.set_region(VoxelBox{{0, 0, 0}, {40, 36, 30}}, 1);
  v.set_region(VoxelBox{{12, 10, 8}, {28, 26, 22}}, 2);  // a structure to cut into
  v.set_region(VoxelBox{{14, 12, 10}, {16, 14, 12}}, 3);
  v.commit();
  const double band = 0.0012;
  StructureDistances distances(v);
  distances.track(2, band);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-0.002, 0.002);
  for (int round = 0; round < 8; ++round) {
    const std::int64_t before = v.revision();
    if (round == 6) {
      v.set_region(VoxelBox{{0, 0, 0}, {2, 2, 2}}, 2);  // beyond its neighbourhood: a new build
    } else {
      const Eigen::Vector3d c(where(rng), where(rng), where(rng));
      v.take_edit_log();
      v.remove_sphere(c, 0.0011, false);
      if (round % 2 == 0) {  // as the drill tells it; odd rounds are seen as others' edits
        const auto log = v.take_edit_log();
        ASSERT_EQ(log.size(), 1u);
        distances.removed(before, log.front().voxels, log.front().old_labels);
      }
    }
    for (std::int64_t t = 0; t <= StructureDistances::kFollowTicks; ++t) distances.tick(true);
    const DistanceField fresh(v, {2}, band);
    const auto& n = v.shape();
    int compared = 0;
    for (int k = 0; k < n[2]; k += 2)
      for (int j = 0; j < n[1]; j += 2)
        for (int i = 0; i < n[0]; i += 2) {
          const Eigen::Vector3d p = v.voxel_center(i, j, k) + Eigen::Vector3d(0.001, -0.0007, 0.0);
          const double want = fresh.sample(p).distance;
          if (std::abs(want) >= band) continue;
          ASSERT_NEAR(distances.distance(2, p), want, 1e-9)
              << round << ": " << i << " " << j << " " << k;
          ++compared;
        }
    EXPECT_GT(compared, 100) << round;
  }
  EXPECT_GE(distances.rebuilds(), 7);
  EXPECT_GE(distances.local_updates(), 5);  // the cuts; round 6 was a new build
  EXPECT_LT(distances.local_updates(), distances.rebuilds());
}

// A replay takes a successor exactly at the tick a real-time run took it (tick_taking), not on
// the kFollowTicks schedule, and says which ticks took what (taken()).
TEST(StructureDistances, ASchedulesTakesAreTheTicksItNames) {
  VolumeData v({40, 36, 30}, Eigen::Vector3d(0.008, 0.0072, 0.009), LabelType::kUInt8, anatomy());
  v.set_region(VoxelBox{{0, 0, 0}, {40, 36, 30}}, 1);
  v.set_region(VoxelBox{{12, 10, 8}, {28, 26, 22}}, 2);
  v.commit();
  const double band = 0.0012;
  StructureDistances scheduled(v);
  StructureDistances plain(v);
  scheduled.track(2, band);
  plain.track(2, band);
  const Eigen::Vector3d inside_cut = v.voxel_center(13, 18, 15);
  const double before_cut = scheduled.distance(2, inside_cut);
  // No successor under way: a schedule that takes one is from another session.
  EXPECT_THROW(scheduled.tick_taking({2}), StateError);
  const std::int64_t revision = v.revision();
  v.take_edit_log();
  v.remove_sphere(inside_cut, 0.0006, false);  // a cut into the structure's face
  const auto log = v.take_edit_log();
  ASSERT_EQ(log.size(), 1u);
  scheduled.removed(revision, log.front().voxels, log.front().old_labels);
  plain.removed(revision, log.front().voxels, log.front().old_labels);
  const std::int64_t late = 3 * StructureDistances::kFollowTicks;
  for (std::int64_t t = 1; t < late; ++t) {
    scheduled.tick_taking({});
    plain.tick(true);
    EXPECT_TRUE(scheduled.taken().empty()) << t;
    if (t == StructureDistances::kFollowTicks + 1) {
      EXPECT_EQ(plain.taken(), std::vector<int>{2});  // the plain schedule took it here
    } else {
      EXPECT_TRUE(plain.taken().empty()) << t;
    }
  }
  // Until the named tick the old field answers, then the successor.
  EXPECT_EQ(scheduled.distance(2, inside_cut), before_cut);
  scheduled.tick_taking({2});
  EXPECT_EQ(scheduled.taken(), std::vector<int>{2});
  EXPECT_GT(scheduled.distance(2, inside_cut), before_cut);
  EXPECT_DOUBLE_EQ(scheduled.distance(2, inside_cut), plain.distance(2, inside_cut));
}

}  // namespace
}  // namespace ambfplus
