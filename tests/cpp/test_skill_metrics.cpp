#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/training/skill_metrics.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {
namespace {

LabelTable anatomy() {
  return LabelTable({Label{1, "Bone", {200, 200, 200}, true, false},
                     Label{2, "Facial nerve", {250, 220, 0}, true, true},
                     Label{3, "Mastoid air cells", {180, 180, 150}, true, false}});
}

// 0.1 mm voxels, bone everywhere.
std::unique_ptr<VolumeData> bone_block() {
  auto v = std::make_unique<VolumeData>(std::array<int, 3>{40, 40, 40},
                                        Eigen::Vector3d(0.004, 0.004, 0.004), LabelType::kUInt8,
                                        anatomy());
  v->set_region(VoxelBox{{0, 0, 0}, {40, 40, 40}}, 1);
  return v;
}

ToolTick tick_at(std::int64_t step, const Eigen::Vector3d& tip, bool cutting, double force = 1.0) {
  ToolTick t;
  t.step = step;
  t.time = (step + 1) * 0.001;
  t.dt = 0.001;
  t.tip = tip;
  t.force = Eigen::Vector3d(0.0, 0.0, force);
  t.burr_radius = 0.0005;
  t.burr_on = true;
  if (cutting) {
    t.removed = {{1, 1, 1}};
    t.removed_labels = {1};
  }
  return t;
}

// A straight stroke at 10 mm/s for 0.5 s: its length, duration and straightness are known.
TEST(SkillMetrics, StraightStrokeOfKnownLengthAndSpeed) {
  const auto block = bone_block();
  VolumeData& v = *block;
  SkillMetrics m(v, MetricsConfig{});
  const double speed = 0.01;
  const int n = 500;
  for (int s = 0; s < n; ++s) {
    m.add(tick_at(s, Eigen::Vector3d(-0.0015 + speed * 0.001 * s, 0.0, 0.0), true));
  }
  for (int s = n; s < n + 100; ++s) m.add(tick_at(s, Eigen::Vector3d::Zero(), false));
  const MetricsSummary sum = m.summary();
  ASSERT_EQ(sum.strokes.size(), 1u);
  const Stroke& stroke = sum.strokes[0];
  EXPECT_NEAR(stroke.length, speed * 0.001 * (n - 1), 1e-12);
  EXPECT_NEAR(stroke.duration, n * 0.001, 1e-9);
  EXPECT_NEAR(stroke.straightness, 1.0, 1e-9);
  EXPECT_EQ(stroke.direction_changes, 0);
  EXPECT_EQ(stroke.voxels, n);
  EXPECT_EQ(stroke.first_step, 0);
  EXPECT_EQ(stroke.last_step, n - 1);
  EXPECT_NEAR(sum.cutting_time, n * 0.001, 1e-9);
  EXPECT_NEAR(sum.burr_on_time, (n + 100) * 0.001, 1e-9);
  EXPECT_NEAR(sum.total_time, (n + 100) * 0.001, 1e-9);
}

// Three legs at right angles make two direction changes and a chord of a third of the path;
// a pause longer than the stroke gap starts a second stroke.
TEST(SkillMetrics, TurnsAndPausesShapeStrokes) {
  const auto block = bone_block();
  VolumeData& v = *block;
  SkillMetrics m(v, MetricsConfig{});
  std::int64_t step = 0;
  Eigen::Vector3d p(-0.001, -0.001, 0.0);
  const Eigen::Vector3d legs[3] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
  m.add(tick_at(step++, p, true));
  for (const Eigen::Vector3d& leg : legs) {
    for (int s = 0; s < 200; ++s) {
      p += leg * 0.00001;  // 10 um per tick: 2 mm per leg
      m.add(tick_at(step++, p, true));
    }
  }
  for (int s = 0; s < 60; ++s) m.add(tick_at(step++, p, false));
  for (int s = 0; s < 10; ++s) m.add(tick_at(step++, p, true));
  const MetricsSummary sum = m.summary();
  ASSERT_EQ(sum.strokes.size(), 2u);
  EXPECT_EQ(sum.strokes[0].direction_changes, 2);
  EXPECT_NEAR(sum.strokes[0].length, 0.006, 1e-9);
  EXPECT_NEAR(sum.strokes[0].straightness, 1.0 / 3.0, 1e-6);
  EXPECT_EQ(sum.strokes[1].first_step, 601 + 60);
}

// Removing a known number of nerve voxels is counted, with the step of the first breach;
// removed voxels are counted by label and by the target region.
TEST(SkillMetrics, KnownNumberOfCriticalVoxelsRemoved) {
  const auto block = bone_block();
  VolumeData& v = *block;
  v.set_region(VoxelBox{{20, 20, 0}, {22, 22, 40}}, 2);  // a nerve along k
  MetricsConfig config;
  config.protect = {{"facial nerve", {2}, 0.001}};
  config.target_labels = {1};
  SkillMetrics m(v, config);
  const Eigen::Vector3d far = v.voxel_center(5, 5, 5);
  std::int64_t step = 0;
  for (int s = 0; s < 10; ++s) {
    ToolTick t = tick_at(step++, far, false);
    t.removed = {{5, 5, s}};
    t.removed_labels = v.remove_voxels(t.removed);
    m.add(t);
  }
  ToolTick breach = tick_at(step++, v.voxel_center(20, 20, 10), false);
  breach.removed = {{20, 20, 10}, {21, 20, 10}, {20, 21, 10}, {19, 20, 10}};
  breach.removed_labels = v.remove_voxels(breach.removed);
  m.add(breach);
  const MetricsSummary sum = m.summary();
  ASSERT_EQ(sum.structures.size(), 1u);
  EXPECT_EQ(sum.structures[0].voxels_removed, 3);
  EXPECT_EQ(sum.structures[0].first_breach_step, 10);
  EXPECT_NEAR(sum.structures[0].first_breach_time, 0.011, 1e-12);
  EXPECT_EQ(sum.removed_by_label.at(1), 11);
  EXPECT_EQ(sum.removed_by_label.at(2), 3);
  EXPECT_EQ(sum.removed_in_target, 11);
  EXPECT_EQ(sum.removed_outside_target, 3);
  // The field followed the breach: the burr sits where nerve voxels were.
  EXPECT_LT(sum.structures[0].closest, 0.0);
}

// The burr passes a one-voxel nerve at 0.5 mm (centre to centre): its closest approach, the
// step of it, the ticks inside a 0.5 mm margin and the force there are known.
TEST(SkillMetrics, KnownClosestApproachAndMargin) {
  const auto block = bone_block();
  VolumeData& v = *block;
  v.set_region(VoxelBox{{15, 15, 15}, {16, 16, 16}}, 2);
  MetricsConfig config;
  config.protect = {{"facial nerve", {2}, 0.0005}};
  SkillMetrics m(v, config);
  for (int s = 0; s <= 20; ++s) {
    ToolTick t = tick_at(s, v.voxel_center(5 + s, 20, 15), false, 2.0 + s);
    m.add(t);
  }
  const StructureMetrics nerve = m.summary().structures.at(0);
  EXPECT_NEAR(nerve.closest, 0.0005 - 0.0005, 1e-9);  // 5 voxels minus the burr radius
  EXPECT_EQ(nerve.closest_step, 10);
  // Inside the margin while |dx|^2 + (0.5 mm)^2 < (1 mm)^2: dx of -8..8 voxels, 17 ticks.
  EXPECT_EQ(nerve.contacts, 1);
  EXPECT_NEAR(nerve.time_in_margin, 0.017, 1e-12);
  EXPECT_NEAR(nerve.force_in_margin_max, 2.0 + 18, 1e-9);
  EXPECT_NEAR(nerve.force_in_margin_mean, 2.0 + 10, 1e-9);
  EXPECT_NEAR(nerve.burr_diameter_in_margin, 0.001, 1e-12);
  EXPECT_EQ(nerve.voxels_removed, 0);
  EXPECT_EQ(nerve.first_breach_step, -1);
}

TEST(SkillMetrics, SessionFarFromStructuresHasNoContact) {
  const auto block = bone_block();
  VolumeData& v = *block;
  v.set_region(VoxelBox{{35, 35, 35}, {38, 38, 38}}, 2);
  MetricsConfig config;
  config.protect = {{"facial nerve", {2}, 0.001}};
  SkillMetrics m(v, config);
  for (int s = 0; s < 100; ++s) m.add(tick_at(s, v.voxel_center(5 + s / 10, 5, 5), true));
  const StructureMetrics nerve = m.summary().structures.at(0);
  EXPECT_EQ(nerve.contacts, 0);
  EXPECT_EQ(nerve.time_in_margin, 0.0);
  EXPECT_GT(nerve.closest, nerve.margin);
}

TEST(SkillMetrics, CuttingForceStatistics) {
  const auto block = bone_block();
  VolumeData& v = *block;
  MetricsConfig config;
  config.excess_force = 80.0;
  SkillMetrics m(v, config);
  for (int s = 0; s < 100; ++s) m.add(tick_at(s, Eigen::Vector3d::Zero(), true, 1.0 + s));
  m.add(tick_at(100, Eigen::Vector3d::Zero(), false, 500.0));  // not cutting: not counted
  const MetricsSummary sum = m.summary();
  EXPECT_NEAR(sum.cutting_force_mean, 50.5, 1e-9);
  EXPECT_NEAR(sum.cutting_force_p95, 95.0, 1e-9);
  EXPECT_NEAR(sum.cutting_force_max, 100.0, 1e-9);
  EXPECT_NEAR(sum.time_above_excess_force, 0.020, 1e-12);
}

// Offline equals live: ticks replayed onto a fresh copy of the anatomy, the metrics removing
// each tick's voxels themselves, give the summary the live metrics gave.
TEST(SkillMetrics, ReplayOntoAFreshAnatomyEqualsLive) {
  const auto live_block = bone_block(), fresh_block = bone_block();
  VolumeData& live = *live_block;
  VolumeData& fresh = *fresh_block;
  for (VolumeData* v : {&live, &fresh}) v->set_region(VoxelBox{{20, 20, 0}, {22, 22, 40}}, 2);
  MetricsConfig config;
  config.protect = {{"facial nerve", {2}, 0.0008}};
  config.target_labels = {1};
  SkillMetrics online(live, config);
  std::vector<ToolTick> ticks;
  for (int s = 0; s < 300; ++s) {
    // Down a column of bone beside the nerve, then into it.
    const int i = 12 + s / 30;
    ToolTick t = tick_at(s, live.voxel_center(i, 20, 20), s % 3 != 0, 1.0 + 0.01 * s);
    if (t.removed.empty()) {
      t.removed_labels.clear();
    } else {
      t.removed = {{i, 20, 20}, {i, 21, 20}};
      t.removed_labels = live.remove_voxels(t.removed);
    }
    online.add(t);
    ticks.push_back(t);
  }
  config.apply_removals = true;
  SkillMetrics offline(fresh, config);
  for (const ToolTick& t : ticks) offline.add(t);
  const MetricsSummary a = online.summary(), b = offline.summary();
  ASSERT_GT(a.structures.at(0).voxels_removed, 0);
  EXPECT_EQ(a.structures[0].voxels_removed, b.structures[0].voxels_removed);
  EXPECT_EQ(a.structures[0].contacts, b.structures[0].contacts);
  EXPECT_EQ(a.structures[0].closest, b.structures[0].closest);
  EXPECT_EQ(a.structures[0].closest_step, b.structures[0].closest_step);
  EXPECT_EQ(a.structures[0].time_in_margin, b.structures[0].time_in_margin);
  EXPECT_EQ(a.removed_by_label, b.removed_by_label);
  EXPECT_EQ(a.strokes.size(), b.strokes.size());
  EXPECT_EQ(a.cutting_force_p95, b.cutting_force_p95);
  // Replaying onto an anatomy that differs is refused, naming the step and the voxel.
  const auto other_block = bone_block();
  SkillMetrics wrong(*other_block, config);
  try {
    for (const ToolTick& t : ticks) wrong.add(t);
    FAIL() << "a replay onto another anatomy was accepted";
  } catch (const StateError& e) {
    EXPECT_NE(std::string(e.what()).find("another anatomy"), std::string::npos) << e.what();
  }
}

TEST(SkillMetrics, RefusesContradictions) {
  const auto block = bone_block();
  VolumeData& v = *block;
  MetricsConfig twice;
  twice.protect = {{"nerve", {2}, 0.001}, {"nerve", {3}, 0.001}};
  EXPECT_THROW(SkillMetrics(v, twice), ArgumentError);
  MetricsConfig no_labels;
  no_labels.protect = {{"nerve", {}, 0.001}};
  EXPECT_THROW(SkillMetrics(v, no_labels), ArgumentError);
  MetricsConfig negative;
  negative.protect = {{"nerve", {2}, -0.001}};
  EXPECT_THROW(SkillMetrics(v, negative), ArgumentError);
  SkillMetrics m(v, MetricsConfig{});
  ToolTick bad = tick_at(0, Eigen::Vector3d::Zero(), true);
  bad.removed_labels.clear();
  EXPECT_THROW(m.add(bad), ArgumentError);
}

}  // namespace
}  // namespace ambfplus
