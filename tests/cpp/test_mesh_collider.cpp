#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "ambfplus//haptics/mesh_collider.h"
#include "ambfplus/errors.h"
#include "ambfplus/haptics/proxy.h"
#include "ambfplus/scene/rigid_body.h"
#include "scene/primitive_meshes.h"

namespace ambfplus {
namespace {

// One triangle in the plane z = 0 with corners (0,0), (1,0), (0,1) (metres).
MeshData unit_triangle() {
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  return m;
}

TEST(MeshCollider, SphereMeetsAFaceAtItsRadius) {
  MeshCollider c;
  c.add_mesh(unit_triangle());
  const MeshHit h = c.sweep({0.2, 0.2, 1.0}, {0.2, 0.2, -1.0}, 0.1);
  ASSERT_TRUE(h.hit);
  // Travels from z = 1 to z = 0.1 of a 2 m path.
  EXPECT_NEAR(h.t, 0.45, 1e-12);
  EXPECT_NEAR(h.normal.z(), 1.0, 1e-12);
  // From below the face works the same way, with the normal reversed.
  const MeshHit under = c.sweep({0.2, 0.2, -1.0}, {0.2, 0.2, 1.0}, 0.1);
  ASSERT_TRUE(under.hit);
  EXPECT_NEAR(under.t, 0.45, 1e-12);
  EXPECT_NEAR(under.normal.z(), -1.0, 1e-12);
}

TEST(MeshCollider, SphereMeetsAnEdgeAndACornerExactly) {
  MeshCollider c;
  c.add_mesh(unit_triangle());
  const double r = 0.1;
  // Moving along -y at z = 0.06, x = 0.5: meets the edge along x (y = 0) when the distance in
  // the y-z plane is r: y = sqrt(r^2 - 0.06^2) = 0.08.
  MeshHit h = c.sweep({0.5, -1.0, 0.06}, {0.5, 1.0, 0.06}, r);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(-1.0 + 2.0 * h.t, -0.08, 1e-12);
  EXPECT_NEAR(h.normal.y(), -0.8, 1e-9);
  EXPECT_NEAR(h.normal.z(), 0.6, 1e-9);
  // Towards the corner (0, 0, 0) from outside the triangle and above it: touches it at r.
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 1, -1).normalized();
  h = c.sweep(-dir, dir, r);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(2.0 * h.t, 1.0 - r, 1e-12);
  EXPECT_NEAR(h.normal.dot(-dir), 1.0, 1e-9);
  // Passing beside the triangle misses it.
  EXPECT_FALSE(c.sweep({1.2, 1.2, 1.0}, {1.2, 1.2, -1.0}, r).hit);
}

TEST(MeshCollider, TouchingBlocksOnlyMotionInwards) {
  MeshCollider c;
  c.add_mesh(unit_triangle());
  const double r = 0.1;
  // Resting on the face: sliding along it or leaving is free, pressing in is not.
  EXPECT_FALSE(c.sweep({0.2, 0.2, r}, {0.3, 0.3, r}, r).hit);
  EXPECT_FALSE(c.sweep({0.2, 0.2, r}, {0.2, 0.2, 1.0}, r).hit);
  const MeshHit press = c.sweep({0.2, 0.2, r}, {0.25, 0.2, 0.0}, r);
  ASSERT_TRUE(press.hit);
  EXPECT_EQ(press.t, 0.0);
}

TEST(MeshCollider, PosedPartsAndPlanes) {
  MeshCollider c;
  const int box = c.add_mesh(make_primitive_mesh(Shape{Shape::Kind::kBox, {0.2, 0.2, 0.2}}));
  // The box centred at x = 1, turned 45 degrees about z: its edge faces -x, at x = 1 - 0.1 sqrt2.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(1, 0, 0));
  pose.rotate(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()));
  c.set_pose(box, pose);
  MeshHit h = c.sweep({0, 0, 0}, {2, 0, 0}, 0.05);
  ASSERT_TRUE(h.hit);
  // (The primitive's vertices are floats.)
  EXPECT_NEAR(2.0 * h.t, 1.0 - 0.1 * std::sqrt(2.0) - 0.05, 1e-6);
  EXPECT_NEAR(h.normal.x(), -1.0, 1e-6);
  // A floor 0.3 below the origin, tilted so its normal is (0, 0.6, 0.8).
  const int floor = c.add_plane();
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.translate(Eigen::Vector3d(0, 0, -0.3));
  tilt.rotate(
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0.6, 0.8)));
  c.set_pose(floor, tilt);
  // Straight down: the sphere's centre is 0.24 above the plane along its normal at the origin,
  // so it touches after 0.24 - r along the normal = (0.24 - 0.04) / 0.8 down.
  h = c.sweep({0, 0, 0}, {0, 0, -1}, 0.04);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 0.2 / 0.8, 1e-12);
  EXPECT_NEAR(h.normal.y(), 0.6, 1e-12);
  EXPECT_NEAR(h.normal.z(), 0.8, 1e-12);
}

TEST(MeshCollider, BadMeshIsRejectedWithTheReason) {
  MeshCollider c;
  MeshData m = unit_triangle();
  m.indices = {0, 1, 7};
  EXPECT_THROW(
      {
        try {
          c.add_mesh(m);
        } catch (const ArgumentError& e) {
          EXPECT_NE(std::string(e.what()).find("index 7"), std::string::npos);
          throw;
        }
      },
      ArgumentError);
}

// The proxy against a box: no voxels at all, only the mesh.
TEST(MeshCollider, ProxyRestsOnABoxAndCannotTunnelThroughAThinOne) {
  auto empty = std::make_shared<VolumeData>(
      std::array<int, 3>{8, 8, 8}, Eigen::Vector3d::Constant(0.0016), LabelType::kUInt8,
      LabelTable({Label{1, "Bone", {255, 255, 255}, true, false}}));
  empty->commit();
  VoxelCollider voxels(empty);
  MeshCollider meshes;
  // A plate 0.5 mm thick, 40 mm wide, its top face at z = 0.
  const int plate =
      meshes.add_mesh(make_primitive_mesh(Shape{Shape::Kind::kBox, {0.04, 0.04, 0.0005}}));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(0, 0, -0.00025));
  meshes.set_pose(plate, pose);
  const double r = 0.001;
  ProxyCursor p(r);
  p.reset(Eigen::Vector3d(0, 0, 0.01));
  // One step to 20 mm below the plate: the sweep stops on it.
  p.update(voxels, Eigen::Vector3d(0.002, 0, -0.01), {}, &meshes);
  ASSERT_EQ(p.contacts(), 1);
  EXPECT_EQ(p.contact_voxel(0)[0], -1) << "a mesh contact";
  EXPECT_NEAR(p.proxy().z(), r, 1e-5);
  EXPECT_NEAR(p.normal(0).z(), 1.0, 1e-9);
  // Pressing and sliding: stays on the face, follows the goal in the plane.
  for (int i = 1; i <= 20; ++i) {
    const Eigen::Vector3d goal(0.002 + 0.0005 * i, 0.0003 * i, -0.0005);
    p.update(voxels, goal, {}, &meshes);
    ASSERT_GE(p.contacts(), 1);
    EXPECT_NEAR(p.proxy().z(), r, 1e-5);
    EXPECT_NEAR(p.proxy().x(), goal.x(), 1e-5);
    EXPECT_NEAR(p.proxy().y(), goal.y(), 1e-5);
  }
}

}  // namespace
}  // namespace ambfplus
