#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "ambfplus/haptics/proxy.h"

namespace ambfplus {
namespace {

constexpr double kVoxel = 0.0002;  // 0.2 mm
constexpr int kN = 100;            // a 20 mm cube centred on the origin

// A volume solid where inside(x, y, z) holds at the voxel centre (metres).
std::shared_ptr<VolumeData> shape(const std::function<bool(double, double, double)>& inside) {
  auto v = std::make_shared<VolumeData>(
      std::array<int, 3>{kN, kN, kN}, Eigen::Vector3d::Constant(kN * kVoxel), LabelType::kUInt8,
      LabelTable({Label{1, "Bone", {255, 255, 255}, true, false}}));
  auto* labels = static_cast<std::uint8_t*>(v->label_data());
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const Eigen::Vector3d c = v->voxel_center(i, j, k);
        labels[v->linear_index(i, j, k)] = inside(c.x(), c.y(), c.z()) ? 1 : 0;
      }
  v->commit();
  return v;
}

// The collision surface of a flat grid face lies on the face: voxel centres are half a voxel
// inside it and each voxel is a sphere of half a voxel.
TEST(Proxy, PlaneHoldsTheProxyOnTheSurfaceAndTheForceAlongTheNormal) {
  VoxelCollider c(shape([](double, double, double z) { return z < 0; }));
  const double r = 0.001;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0.0003, -0.0007, 0.003));
  for (double lateral : {0.0, 0.001, 0.002}) {
    const Eigen::Vector3d goal(0.0003 + lateral, -0.0007, r - 0.0005);  // 0.5 mm deep
    p.update(c, goal);
    ASSERT_EQ(p.contacts(), 1);
    // On the surface within the ripple of voxel spheres, s^2 / 4(r + s/2) = 9 um here.
    EXPECT_NEAR(p.proxy().z(), r, 1e-5) << "on the surface";
    EXPECT_NEAR(p.proxy().x(), goal.x(), 1e-5) << "slides freely in the plane";
    EXPECT_NEAR(p.proxy().y(), goal.y(), 1e-5);
    const Eigen::Vector3d force = 500.0 * (p.proxy() - p.goal());
    EXPECT_NEAR(force.z(), 500.0 * 0.0005, 500.0 * 1e-5);
    EXPECT_LT(std::hypot(force.x(), force.y()), 0.02 * force.z());
    EXPECT_GT(p.normal(0).z(), 0.999);
  }
  // Pulled back out, it follows the goal and touches nothing.
  p.update(c, Eigen::Vector3d(0.0, 0.0, 0.004));
  EXPECT_EQ(p.contacts(), 0);
  EXPECT_TRUE(p.proxy().isApprox(Eigen::Vector3d(0.0, 0.0, 0.004)));
}

TEST(Proxy, SphereForcePointsToItsCentre) {
  const double R = 0.005;
  VoxelCollider c(
      shape([&](double x, double y, double z) { return x * x + y * y + z * z < R * R; }));
  const double r = 0.001;
  for (const Eigen::Vector3d dir : {Eigen::Vector3d(1, 0.3, 0.5), Eigen::Vector3d(-0.2, -1, 0.7),
                                    Eigen::Vector3d(0.1, 0.2, -1)}) {
    const Eigen::Vector3d u = dir.normalized();
    ProxyCursor p(r);
    p.reset(u * (R + r + 0.002));
    p.update(c, u * (R + r - 0.0005));
    ASSERT_GE(p.contacts(), 1);
    const Eigen::Vector3d force = p.proxy() - p.goal();
    const double angle = std::acos(force.normalized().dot(u));
    // A sphere of 25 voxels' radius is a staircase; its smoothed normals are within 2 degrees.
    EXPECT_LT(angle, 0.05) << "radians off the radial direction";
    EXPECT_NEAR(p.proxy().norm(), R + r, 0.5 * kVoxel);
  }
}

TEST(Proxy, CreaseGivesTwoContactsAndSlidesAlongIt) {
  // Solid where x < 0 or z < 0: a valley along y.
  VoxelCollider c(shape([](double x, double, double z) { return x < 0 || z < 0; }));
  const double r = 0.001;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0.003, 0.0, 0.003));
  p.update(c, Eigen::Vector3d(0.0005, 0.0, 0.0005));
  ASSERT_EQ(p.contacts(), 2);
  EXPECT_NEAR(p.proxy().x(), r, 1e-5);
  EXPECT_NEAR(p.proxy().z(), r, 1e-5);
  // Pushed into the valley and along it, the proxy slides along the crease.
  p.update(c, Eigen::Vector3d(0.0005, 0.002, 0.0005));
  EXPECT_EQ(p.contacts(), 2);
  EXPECT_NEAR(p.proxy().y(), 0.002, 1e-5);
  EXPECT_NEAR(p.proxy().x(), r, 1e-5);
  EXPECT_NEAR(p.proxy().z(), r, 1e-5);
}

TEST(Proxy, CornerGivesThreeContacts) {
  VoxelCollider c(shape([](double x, double y, double z) { return x < 0 || y < 0 || z < 0; }));
  const double r = 0.001;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0.003, 0.003, 0.003));
  p.update(c, Eigen::Vector3d(0.0004, 0.0004, 0.0004));
  ASSERT_EQ(p.contacts(), 3);
  EXPECT_TRUE(p.proxy().isApprox(Eigen::Vector3d::Constant(r), 0.01));
}

TEST(Proxy, FrictionKeepsTheProxyInsideTheCone) {
  VoxelCollider c(shape([](double, double, double z) { return z < 0; }));
  const double r = 0.001, mu = 0.5, depth = 0.0005;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0, 0, 0.003));
  const Friction friction{mu, mu};
  p.update(c, Eigen::Vector3d(0, 0, r - depth), friction);
  ASSERT_GE(p.contacts(), 1);
  // A small pull (inside the cone, mu * depth = 0.25 mm) leaves the proxy where it is.
  p.update(c, Eigen::Vector3d(0.0001, 0, r - depth), friction);
  EXPECT_NEAR(p.proxy().x(), 0.0, 1e-5);
  // A larger one drags it to the rim of the cone.
  for (double x : {0.0005, 0.001, 0.0015}) {
    p.update(c, Eigen::Vector3d(x, 0, r - depth), friction);
    const double tangential = std::abs(p.proxy().x() - p.goal().x());
    const double normal = p.proxy().z() - p.goal().z();
    EXPECT_NEAR(tangential, mu * normal, 1e-5) << x;
    EXPECT_GT(p.proxy().x(), 0.0001) << "it slid";
  }
}

TEST(Proxy, FastGoalNeverTunnelsThroughAThinWall) {
  // A 1 mm wall in 0 <= z < 1 mm; the goal crosses it at 2 m/s in 1 ms steps (2 mm per step).
  // (Spheres of half a voxel on a grid leave dips of s^2 / 8(r + s/2) = 8 um between them.)
  VoxelCollider c(shape([](double, double, double z) { return z >= 0 && z < 0.001; }));
  const double r = 0.0005;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0, 0, 0.008));
  for (double z = 0.008; z >= -0.009; z -= 0.002) {
    p.update(c, Eigen::Vector3d(0.0001, 0.0002, z));
    EXPECT_GE(p.proxy().z(), 0.001 + r - 1e-5) << "goal at z = " << z;
  }
  EXPECT_GE(p.contacts(), 1);
}

// The gathered query tests far fewer voxels than the cube scan, with the same first contact.
TEST(Collider, GatherFindsTheSameContactAsTheFullCubeScan) {
  VoxelCollider c(shape([](double x, double y, double z) {
    return z < 0.0003 * std::sin(x * 2000) + 0.0002 * std::cos(y * 3000);
  }));
  for (const Eigen::Vector3d a :
       {Eigen::Vector3d(0.001, 0.002, 0.004), Eigen::Vector3d(-0.003, 0.0, 0.003)}) {
    const Eigen::Vector3d b = a - Eigen::Vector3d(0.0005, -0.0003, 0.006);
    c.reset_counters();
    const SweepHit gather = c.sweep(a, b, 0.003);
    const std::int64_t gathered = c.voxels_tested();
    c.reset_counters();
    const SweepHit full = c.sweep_full_cube(a, b, 0.003);
    ASSERT_TRUE(gather.hit && full.hit);
    EXPECT_NEAR(gather.t, full.t, 1e-12);
    EXPECT_EQ(gather.voxel, full.voxel);
    EXPECT_LT(gathered * 5, c.voxels_tested());
  }
}

TEST(Collider, RemovalUpdatesTheSurface) {
  VoxelCollider c(shape([](double, double, double z) { return z < 0; }));
  EXPECT_TRUE(c.surface(50, 50, 49));
  EXPECT_FALSE(c.surface(50, 50, 48));
  const std::vector<std::uint16_t> old = c.remove({{50, 50, 49}});
  EXPECT_EQ(old[0], 1);
  EXPECT_FALSE(c.solid(50, 50, 49));
  EXPECT_TRUE(c.surface(50, 50, 48)) << "the voxel below is exposed";
  // Edits made directly in the volume are picked up by sync().
  c.data()->set_region(VoxelBox{{10, 10, 49}, {12, 12, 50}}, 0);
  c.sync();
  EXPECT_TRUE(c.surface(10, 10, 48));
}

}  // namespace
}  // namespace ambfplus
