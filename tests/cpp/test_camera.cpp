#include <gtest/gtest.h>

#include <cmath>

#include "ambfplus/engine/engine.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/simulator.h"

namespace ambfplus {
namespace {

Camera& make_camera(World& world, int w, int h, double fov) {
  CameraSpec spec;
  spec.name = "cam";
  spec.width = w;
  spec.height = h;
  spec.fov_y = fov;
  spec.near = 0.01;
  spec.far = 100;
  return world.default_model().add_camera(spec);
}

TEST(Camera, IntrinsicsFollowThePaper) {
  auto sim = engine::create_simulator();
  Camera& cam = make_camera(sim->world(), 640, 480, 0.7);
  const Eigen::Matrix3d k = cam.intrinsics();
  EXPECT_DOUBLE_EQ(k(0, 0), 480 / (2 * std::tan(0.35)));
  EXPECT_DOUBLE_EQ(k(1, 1), k(0, 0));
  EXPECT_DOUBLE_EQ(k(0, 2), 320);
  EXPECT_DOUBLE_EQ(k(1, 2), 240);
}

// The projection matrix must agree with K: window coordinates equal continuous pixel coordinates,
// and the reversed depth runs from 1 at near to 0 at far.
TEST(Camera, ProjectionAgreesWithIntrinsics) {
  auto sim = engine::create_simulator();
  Camera& cam = make_camera(sim->world(), 320, 200, 1.1);
  const Eigen::Matrix3d k = cam.intrinsics();
  const Eigen::Matrix4d p = cam.projection();
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.1, -0.2, 1.5), Eigen::Vector3d(-3, 2, 40)}) {
    const Eigen::Vector4d clip = p * x.homogeneous();
    const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    const Eigen::Vector3d uv = k * x / x.z();
    EXPECT_NEAR((ndc.x() + 1) / 2 * cam.width(), uv.x(), 1e-9);
    EXPECT_NEAR((ndc.y() + 1) / 2 * cam.height(), uv.y(), 1e-9);
  }
  const Eigen::Vector4d at_near = p * Eigen::Vector4d(0, 0, cam.near(), 1);
  const Eigen::Vector4d at_far = p * Eigen::Vector4d(0, 0, cam.far(), 1);
  EXPECT_NEAR(at_near.z() / at_near.w(), 1.0, 1e-12);
  EXPECT_NEAR(at_far.z() / at_far.w(), 0.0, 1e-12);
}

TEST(Camera, LookAtPointsTheOpticalAxisAndKeepsUpUp) {
  auto sim = engine::create_simulator();
  Camera& cam = make_camera(sim->world(), 64, 48, 0.7);
  cam.look_at({1, 2, 3}, {1, 5, 3}, {0, 0, 1});
  const Eigen::Isometry3d pose = cam.pose();
  EXPECT_TRUE(pose.linear().col(2).isApprox(Eigen::Vector3d(0, 1, 0)));
  // Image down (+y) is world -z when up is +z.
  EXPECT_TRUE(pose.linear().col(1).isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_NEAR(pose.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_THROW(cam.look_at({0, 0, 0}, {0, 0, 1}, {0, 0, 1}), ArgumentError);
  EXPECT_THROW(cam.look_at({0, 0, 0}, {0, 0, 0}), ArgumentError);
}

TEST(Camera, RejectsBadSpecs) {
  auto sim = engine::create_simulator();
  CameraSpec spec;
  spec.name = "bad";
  spec.near = 1;
  spec.far = 0.5;
  EXPECT_THROW(sim->world().default_model().add_camera(spec), ArgumentError);
  spec.near = 0.1;
  spec.far = 10;
  spec.width = 0;
  EXPECT_THROW(sim->world().default_model().add_camera(spec), ArgumentError);
}

}  // namespace
}  // namespace ambfplus
