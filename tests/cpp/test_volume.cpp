#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "ambfplus/volume/volume_data.h"
#include "render/volume_renderer.h"
#include "volume/grid_access.h"

namespace ambfplus {
namespace {

LabelTable bone() { return LabelTable({Label{1, "Bone", {200, 200, 200}, true, false}}); }

TEST(VoxelBox, UnionClipGrow) {
  const VoxelBox a{{0, 0, 0}, {2, 2, 2}}, b{{5, 1, 1}, {6, 3, 4}};
  EXPECT_EQ(a.united(b), (VoxelBox{{0, 0, 0}, {6, 3, 4}}));
  EXPECT_EQ(VoxelBox().united(b), b);
  EXPECT_EQ(b.grown(2).clipped({6, 6, 6}), (VoxelBox{{3, 0, 0}, {6, 5, 6}}));
  EXPECT_EQ(a.count(), 8);
  EXPECT_TRUE((VoxelBox{{1, 1, 1}, {1, 5, 5}}).empty());
}

// A flat boundary between solid (i < 8) and empty voxels: the smoothed field crosses 0.5 exactly
// on the boundary plane, and is symmetric about it.
TEST(SmoothedOccupancy, FlatBoundarySitsOnTheVoxelFace) {
  VolumeData v({16, 6, 6}, Eigen::Vector3d(0.016, 0.006, 0.006), LabelType::kUInt8, bone());
  v.set_region(VoxelBox{{0, 0, 0}, {8, 6, 6}}, 1);
  const VolumeField f{v.smoothed_occupancy().data(), v.shape()};
  EXPECT_NEAR(f.sample(Eigen::Vector3d(8.0, 3.0, 3.0)), 127.5, 1.0);
  for (double d : {0.3, 0.7, 1.2, 2.0}) {
    const double in = f.sample(Eigen::Vector3d(8.0 - d, 3.0, 3.0));
    const double out = f.sample(Eigen::Vector3d(8.0 + d, 3.0, 3.0));
    EXPECT_NEAR(in + out, 255.0, 1.5) << d;
    EXPECT_GT(in, out);
  }
}

// Incremental updates of the derived fields equal recomputing them from scratch.
TEST(SmoothedOccupancy, IncrementalEqualsFromScratch) {
  std::mt19937 rng(3);
  VolumeData v({24, 20, 18}, Eigen::Vector3d::Constant(0.02), LabelType::kUInt8, bone());
  auto* labels = static_cast<std::uint8_t*>(v.label_data());
  for (std::int64_t n = 0; n < v.voxel_count(); ++n) labels[n] = rng() % 3 == 0;
  v.mark_dirty(VoxelBox{{0, 0, 0}, v.shape()});
  (void)v.brick_max();
  v.remove_sphere(Eigen::Vector3d(0.001, -0.002, 0.0), 0.004);
  v.set_region(VoxelBox{{2, 3, 4}, {5, 9, 6}}, 1);
  const auto smoothed = v.smoothed_occupancy();
  const auto bricks = v.brick_max();
  VolumeData fresh({24, 20, 18}, Eigen::Vector3d::Constant(0.02), LabelType::kUInt8, bone());
  std::copy(labels, labels + v.voxel_count(), static_cast<std::uint8_t*>(fresh.label_data()));
  EXPECT_EQ(fresh.smoothed_occupancy(), smoothed);
  EXPECT_EQ(fresh.brick_max(), bricks);
}

// More edits between two reads than the derived fields keep boxes for (they merge): still
// equal to recomputing from scratch.
TEST(SmoothedOccupancy, ManyEditsBetweenReadsEqualFromScratch) {
  std::mt19937 rng(5);
  VolumeData v({30, 26, 22}, Eigen::Vector3d::Constant(0.03), LabelType::kUInt16, bone());
  auto* labels = static_cast<std::uint16_t*>(v.label_data());
  for (std::int64_t n = 0; n < v.voxel_count(); ++n) labels[n] = rng() % 2 ? 1 : 0;
  v.mark_dirty(VoxelBox{{0, 0, 0}, v.shape()});
  (void)v.smoothed_occupancy();
  for (int e = 0; e < 100; ++e) {
    const std::array<int, 3> at{int(rng() % 30), int(rng() % 26), int(rng() % 22)};
    v.remove_voxels({at});
  }
  VolumeData fresh({30, 26, 22}, Eigen::Vector3d::Constant(0.03), LabelType::kUInt16, bone());
  std::copy(labels, labels + v.voxel_count(), static_cast<std::uint16_t*>(fresh.label_data()));
  EXPECT_EQ(fresh.smoothed_occupancy(), v.smoothed_occupancy());
  EXPECT_EQ(fresh.brick_max(), v.brick_max());
}

// The derived fields of a box computed from a packed copy of the labels around it (as a
// renderer does off the world's lock) equal the volume's own, for 1- and 2-byte labels.
TEST(SmoothedOccupancy, FromAPackedCopyEqualsTheVolumes) {
  for (const LabelType type : {LabelType::kUInt8, LabelType::kUInt16}) {
    std::mt19937 rng(11);
    const std::array<int, 3> shape{21, 19, 17};
    VolumeData v(shape, Eigen::Vector3d::Constant(0.02), type, bone());
    const int bytes = type == LabelType::kUInt16 ? 2 : 1;
    auto* raw = static_cast<std::uint8_t*>(v.label_data());
    for (std::int64_t n = 0; n < v.voxel_count(); ++n) raw[n * bytes] = rng() % 3 == 0;
    v.mark_dirty(VoxelBox{{0, 0, 0}, shape});
    const std::vector<std::uint8_t> whole_smoothed = v.smoothed_occupancy();
    const std::vector<std::uint8_t> whole_bricks = v.brick_max();
    // An edited box touching the grid's edge on one side: its bricks, their footprints and
    // the labels the smoothing of those needs.
    const VoxelBox edited{{0, 5, 7}, {6, 11, 12}};
    const VoxelBox bricks =
        bricks_reaching(edited.grown(VolumeData::kSmoothRadius).clipped(shape), shape);
    const VoxelBox footprints = brick_footprints(bricks, shape);
    const VoxelBox frame = footprints.grown(VolumeData::kSmoothRadius).clipped(shape);
    std::vector<std::uint8_t> copy;
    for (int k = frame.lo[2]; k < frame.hi[2]; ++k)
      for (int j = frame.lo[1]; j < frame.hi[1]; ++j)
        for (int i = frame.lo[0]; i < frame.hi[0]; ++i)
          for (int b = 0; b < bytes; ++b) copy.push_back(raw[v.linear_index(i, j, k) * bytes + b]);
    std::vector<std::uint8_t> smoothed(static_cast<std::size_t>(footprints.count()));
    smooth_occupancy(copy.data(), frame, bytes, shape, footprints, smoothed.data(), footprints);
    std::size_t at = 0;
    for (int k = footprints.lo[2]; k < footprints.hi[2]; ++k)
      for (int j = footprints.lo[1]; j < footprints.hi[1]; ++j)
        for (int i = footprints.lo[0]; i < footprints.hi[0]; ++i, ++at)
          ASSERT_EQ(smoothed[at], whole_smoothed[v.linear_index(i, j, k)]) << i << " " << j;
    std::vector<std::uint8_t> maxima(static_cast<std::size_t>(bricks.count()));
    brick_maxima(smoothed.data(), footprints, shape, bricks, maxima.data(), bricks);
    const auto bs = v.brick_shape();
    at = 0;
    for (int k = bricks.lo[2]; k < bricks.hi[2]; ++k)
      for (int j = bricks.lo[1]; j < bricks.hi[1]; ++j)
        for (int i = bricks.lo[0]; i < bricks.hi[0]; ++i, ++at)
          ASSERT_EQ(maxima[at],
                    whole_bricks[i + std::size_t(bs[0]) * (j + std::size_t(bs[1]) * k)]);
  }
}

// More edits than the history keeps: what is no longer listed counts as the union of the
// dropped boxes (the corner edited), not the whole grid, so a late reader copies little.
TEST(VolumeData, EditsBeyondTheHistoryStayWithinTheirUnion) {
  VolumeData v({64, 64, 64}, Eigen::Vector3d::Constant(0.064), LabelType::kUInt8, bone());
  const std::int64_t start = v.revision();
  for (int e = 0; e < 5000; ++e) v.mark_dirty(VoxelBox{{e % 8, 2, 3}, {e % 8 + 1, 3, 4}});
  v.mark_dirty(VoxelBox{{60, 60, 60}, {61, 61, 61}});
  VoxelBox box;
  ASSERT_TRUE(v.dirty_since(start, &box));
  EXPECT_EQ(box, (VoxelBox{{0, 2, 3}, {61, 61, 61}}));
  std::vector<VoxelBox> boxes;
  ASSERT_TRUE(v.dirty_boxes_since(start, &boxes));
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes.front(), (VoxelBox{{0, 2, 3}, {8, 3, 4}}));
  EXPECT_EQ(boxes.back(), (VoxelBox{{60, 60, 60}, {61, 61, 61}}));
}

TEST(VolumeData, DirtySinceUnitesLaterEdits) {
  VolumeData v({10, 10, 10}, Eigen::Vector3d::Constant(0.01), LabelType::kUInt8, bone());
  const std::int64_t r0 = v.revision();
  VoxelBox box;
  EXPECT_FALSE(v.dirty_since(r0, &box));
  v.mark_dirty(VoxelBox{{1, 1, 1}, {2, 2, 2}});
  const std::int64_t r1 = v.revision();
  v.mark_dirty(VoxelBox{{5, 5, 5}, {7, 6, 6}});
  ASSERT_TRUE(v.dirty_since(r0, &box));
  EXPECT_EQ(box, (VoxelBox{{1, 1, 1}, {7, 6, 6}}));
  ASSERT_TRUE(v.dirty_since(r1, &box));
  EXPECT_EQ(box, (VoxelBox{{5, 5, 5}, {7, 6, 6}}));
}

// A tool's consecutive edits make one box; an edit far away stays a box of its own.
TEST(VolumeData, DirtyBoxesKeepFarEditsApart) {
  VolumeData v({64, 64, 64}, Eigen::Vector3d::Constant(0.064), LabelType::kUInt8, bone());
  const std::int64_t r0 = v.revision();
  v.mark_dirty(VoxelBox{{10, 10, 10}, {14, 14, 14}});
  v.mark_dirty(VoxelBox{{11, 10, 10}, {15, 14, 14}});
  v.mark_dirty(VoxelBox{{50, 50, 50}, {54, 54, 54}});
  std::vector<VoxelBox> boxes;
  ASSERT_TRUE(v.dirty_boxes_since(r0, &boxes));
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0], (VoxelBox{{10, 10, 10}, {15, 14, 14}}));
  EXPECT_EQ(boxes[1], (VoxelBox{{50, 50, 50}, {54, 54, 54}}));
  // Beyond max_boxes, one union.
  ASSERT_TRUE(v.dirty_boxes_since(r0, &boxes, 1));
  EXPECT_EQ(boxes, (std::vector<VoxelBox>{VoxelBox{{10, 10, 10}, {54, 54, 54}}}));
  EXPECT_FALSE(v.dirty_boxes_since(v.revision(), &boxes));
}

// The edit log keeps the newest edits up to its caps and counts those it dropped.
TEST(VolumeData, EditLogIsCapped) {
  VolumeData v({8, 8, 8}, Eigen::Vector3d::Constant(0.008), LabelType::kUInt8, bone());
  const std::size_t extra = 10;
  for (std::size_t n = 0; n < VolumeData::kEditLogEdits + extra; ++n) {
    v.mark_dirty(VoxelBox{{0, 0, 0}, {1, 1, 1}});
  }
  EXPECT_EQ(v.edit_log().size(), VolumeData::kEditLogEdits);
  EXPECT_EQ(v.edit_log_dropped(), static_cast<std::int64_t>(extra));
  EXPECT_EQ(v.edit_log().back().revision, v.revision());
  EXPECT_EQ(v.take_edit_log().size(), VolumeData::kEditLogEdits);
  EXPECT_TRUE(v.edit_log().empty());
}

// The two-pass distance map equals a brute-force Chebyshev distance to the nearest occupied brick.
TEST(BrickDistances, MatchBruteForce) {
  const std::array<int, 3> n = {9, 7, 11};
  std::mt19937 rng(5);
  std::vector<std::uint8_t> max(9 * 7 * 11, 0);
  for (auto& m : max) m = rng() % 40 == 0 ? 200 : 10;
  const auto d = render::brick_distances(max, n, 127);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        int best = 255;
        for (int c = 0; c < n[2]; ++c)
          for (int b = 0; b < n[1]; ++b)
            for (int a = 0; a < n[0]; ++a) {
              if (max[a + n[0] * (b + n[1] * c)] < 127) continue;
              best = std::min(best, std::max({std::abs(a - i), std::abs(b - j), std::abs(c - k)}));
            }
        ASSERT_EQ(d[i + n[0] * (j + n[1] * k)], best) << i << "," << j << "," << k;
      }
}

TEST(VolumeData, RaycastHitsAFlatFaceAtItsPlane) {
  VolumeData v({20, 20, 20}, Eigen::Vector3d::Constant(0.02), LabelType::kUInt8, bone());
  v.set_region(VoxelBox{{0, 0, 0}, {20, 20, 10}}, 1);  // solid below z = 0
  const VolumeHit hit = v.raycast(Eigen::Vector3d(0.001, 0.002, 0.05), Eigen::Vector3d(0.1, 0, -1));
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.position.z(), 0.0, 0.0001);
  EXPECT_TRUE(hit.normal.isApprox(Eigen::Vector3d::UnitZ(), 1e-3));
  EXPECT_EQ(hit.label, 1);
  EXPECT_FALSE(v.raycast(Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d(1, 0, 0)).hit);
}

// Whether every input box lies in one of the merged boxes.
bool covered(const std::vector<VoxelBox>& inputs, const std::vector<VoxelBox>& merged) {
  return std::all_of(inputs.begin(), inputs.end(), [&](const VoxelBox& in) {
    return in.empty() || std::any_of(merged.begin(), merged.end(),
                                     [&](const VoxelBox& m) { return m.united(in) == m; });
  });
}

// A burr's scattered one-voxel removals between two captures become one box to copy; edits
// far from them stay boxes of their own.
TEST(CoalesceBoxes, JoinsNearbyEditsAndKeepsFarOnesApart) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> near(100, 120);
  std::vector<VoxelBox> boxes;
  for (int n = 0; n < 50; ++n) {
    const std::array<int, 3> lo{near(rng), near(rng), near(rng)};
    boxes.push_back(VoxelBox{lo, {lo[0] + 1, lo[1] + 1, lo[2] + 1}});
  }
  boxes.push_back(VoxelBox{{10, 10, 10}, {12, 12, 12}});
  boxes.push_back(VoxelBox{{200, 10, 10}, {203, 11, 11}});
  boxes.push_back(VoxelBox{});  // an empty edit
  boxes.push_back(VoxelBox{{10, 200, 200}, {11, 201, 201}});
  const std::vector<VoxelBox> inputs = boxes;
  render::coalesce_boxes(boxes, 2, 8, 4096);
  EXPECT_TRUE(covered(inputs, boxes));
  ASSERT_EQ(boxes.size(), 4u);
  const VoxelBox cluster{{100, 100, 100}, {121, 121, 121}};
  EXPECT_EQ(std::count_if(boxes.begin(), boxes.end(),
                          [&](const VoxelBox& b) { return cluster.united(b) == cluster; }),
            1);
}

TEST(CoalesceBoxes, MergesFarEditsBeyondTheLimit) {
  std::vector<VoxelBox> boxes;
  for (int n = 0; n < 12; ++n) {
    const int at = 20 * n;
    boxes.push_back(VoxelBox{{at, 0, 250 - at}, {at + 1, 1, 251 - at}});
  }
  const std::vector<VoxelBox> inputs = boxes;
  render::coalesce_boxes(boxes, 2, 8, 4096);
  EXPECT_LE(boxes.size(), 8u);
  EXPECT_GE(boxes.size(), 1u);
  EXPECT_TRUE(covered(inputs, boxes));
  std::vector<VoxelBox> none{VoxelBox{}};
  render::coalesce_boxes(none, 2, 8, 4096);
  EXPECT_TRUE(none.empty());
}

// The obscurance field of a half-space (solid below z = 32 voxels) is the share of its Gaussian
// below the plane: the discrete weights' tail exactly, and the normal tail of sigma 2 cells
// (4 voxels) within sampling error.
TEST(Obscurance, AHalfSpaceGivesTheGaussiansTail) {
  const std::array<int, 3> shape = {64, 64, 64};
  std::vector<std::uint8_t> labels(64 * 64 * 64, 0);
  for (int k = 0; k < 32; ++k) std::fill_n(labels.begin() + k * 64 * 64, 64 * 64, 1);
  const auto cells = render::obscurance_cells(shape);
  ASSERT_EQ(cells, (std::array<int, 3>{32, 32, 32}));
  std::vector<std::uint8_t> counts(32 * 32 * 32, 99);
  const VoxelBox all{{0, 0, 0}, shape}, all_cells{{0, 0, 0}, cells};
  render::count_cell_occupancy(labels.data(), all, 1, shape, all_cells, counts.data());
  for (int k = 0; k < 32; ++k) EXPECT_EQ(counts[16 + 32 * (16 + 32 * k)], k < 16 ? 8 : 0);
  const auto field = render::blur_cell_occupancy(counts, cells, all_cells);
  constexpr int R = render::kObscuranceReach;
  double weights[2 * R + 1], total = 0;
  for (int t = -R; t <= R; ++t) {
    weights[t + R] = std::exp(-0.5 * t * t / (render::kObscuranceSigma * render::kObscuranceSigma));
    total += weights[t + R];
  }
  for (int k = 8; k < 24; ++k) {
    double tail = 0;  // the weights of the cells below the plane
    for (int t = -R; t <= R; ++t) tail += k + t < 16 ? weights[t + R] / total : 0.0;
    const double value = field[16 + 32 * (16 + 32 * k)] / 255.0;
    EXPECT_NEAR(value, tail, 0.6 / 255) << "cell " << k;
    // Cell k's centre lies 2k + 1 - 32 voxels above the plane.
    const double d = 2.0 * k + 1.0 - 32.0;
    EXPECT_NEAR(value, 0.5 * std::erfc(d / (4.0 * std::sqrt(2.0))), 0.03) << "cell " << k;
  }
  // Beyond the Gaussian's reach of the plane: all solid, or nothing; and near the grid's floor
  // the cells outside count as empty (open ground there, as the texture's border says).
  EXPECT_EQ(field[16 + 32 * (16 + 32 * 9)], 255);
  EXPECT_EQ(field[16 + 32 * (16 + 32 * 22)], 0);
  EXPECT_LT(field[16 + 32 * (16 + 32 * 2)], 240);
}

// A box of the field, as a drilling edit recomputes it, equals the same cells of the whole
// field; an odd-sized grid's last cells count only the voxels inside it; 16-bit labels count
// alike.
TEST(Obscurance, ABoxEqualsTheWholeFieldsCells) {
  const std::array<int, 3> shape = {23, 18, 15};
  std::mt19937 rng(11);
  std::vector<std::uint16_t> labels(23 * 18 * 15);
  for (auto& l : labels) l = rng() % 3 == 0 ? 0 : 300 + rng() % 5;
  const auto cells = render::obscurance_cells(shape);
  ASSERT_EQ(cells, (std::array<int, 3>{12, 9, 8}));
  std::vector<std::uint8_t> counts(12 * 9 * 8);
  const VoxelBox all{{0, 0, 0}, shape}, all_cells{{0, 0, 0}, cells};
  render::count_cell_occupancy(reinterpret_cast<const std::uint8_t*>(labels.data()), all, 2, shape,
                               all_cells, counts.data());
  // The last cell along i holds voxel 22 only (one column of 2 x 2 in j, k).
  int solid = 0;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j) solid += labels[22 + 23 * (j + 18 * k)] != 0;
  EXPECT_EQ(counts[11], solid);
  const auto whole = render::blur_cell_occupancy(counts, cells, all_cells);
  const VoxelBox box{{3, 1, 2}, {9, 7, 5}};
  const auto part = render::blur_cell_occupancy(counts, cells, box);
  ASSERT_EQ(part.size(), std::size_t(box.count()));
  std::size_t at = 0;
  for (int k = box.lo[2]; k < box.hi[2]; ++k)
    for (int j = box.lo[1]; j < box.hi[1]; ++j)
      for (int i = box.lo[0]; i < box.hi[0]; ++i) {
        ASSERT_EQ(part[at++], whole[i + 12 * (j + 9 * k)]) << i << "," << j << "," << k;
      }
}

}  // namespace
}  // namespace ambfplus

TEST(LabelTable, BoneIsNamedOrTheOnlyMaterial) {
  // The original system's ear: its bony labels take the bone texture, soft tissue does not.
  const char* const names[] = {"Bone",
                               "Malleus",
                               "Incus",
                               "Stapes",
                               "Bony_Labyrinth",
                               "IAC",
                               "Superior_Vestibular_Nerve",
                               "Facial_Nerve",
                               "Chorda_Tympani",
                               "ICA",
                               "Sinus_+_Dura",
                               "Vestibular_Aqueduct",
                               "TMJ",
                               "EAC"};
  ambfplus::LabelTable ear;
  std::uint16_t id = 0;
  for (const char* name : names) ear.add(ambfplus::Label{++id, name, {255, 255, 255}, true, false});
  std::vector<std::string> bone;
  for (const ambfplus::Label& l : ear.labels()) {
    if (ambfplus::is_bone(ear, l)) bone.push_back(l.name);
  }
  EXPECT_EQ(bone,
            (std::vector<std::string>{"Bone", "Malleus", "Incus", "Stapes", "Bony_Labyrinth"}));
  EXPECT_TRUE(ambfplus::is_bone(ear, ambfplus::Label{99, "mastoid CORTEX", {}, true, false}));
  // A one-material volume (a thresholded CT's "Segmented") is bone, whatever its name.
  const ambfplus::LabelTable one({ambfplus::Label{1, "Segmented", {255, 249, 219}, true, false}});
  EXPECT_TRUE(ambfplus::is_bone(one, one.labels()[0]));
}
