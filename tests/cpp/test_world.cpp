#include <gtest/gtest.h>

#include <stdexcept>

#include "ambfplus/scene/simulator.h"

namespace ambfplus {
namespace {

RigidBodySpec sphere(const std::string& name) {
  RigidBodySpec spec;
  spec.name = name;
  spec.shape.kind = Shape::Kind::kSphere;
  spec.shape.radius = 0.1;
  return spec;
}

TEST(World, NamesAreUniqueAcrossModels) {
  auto sim = Simulator::create();
  World& world = sim->world();
  world.default_model().add_body(sphere("a"));
  Model& other = world.add_model("other");
  EXPECT_THROW(other.add_body(sphere("a")), std::invalid_argument);
  CameraSpec camera;
  camera.name = "a";
  EXPECT_THROW(other.add_camera(camera), std::invalid_argument);
  EXPECT_EQ(world.objects().size(), 1u);
}

TEST(World, IdsAreStableAndNotReusedAfterAFailedAdd) {
  auto sim = Simulator::create();
  World& world = sim->world();
  const int a = world.default_model().add_body(sphere("a")).id();
  RigidBodySpec bad = sphere("bad");
  bad.shape.radius = -1;
  EXPECT_THROW(world.default_model().add_body(bad), std::invalid_argument);
  EXPECT_EQ(world.find("bad"), nullptr);
  const int b = world.default_model().add_body(sphere("b")).id();
  EXPECT_EQ(a, 1);
  EXPECT_GT(b, a);
  EXPECT_EQ(world.find("a")->id(), a);
}

TEST(World, ClockCountsFixedStepsWithoutDrift) {
  SimulatorOptions options;
  options.time_step = 0.001;
  auto sim = Simulator::create(options);
  for (int i = 0; i < 1000; ++i) sim->step();
  EXPECT_EQ(sim->world().step_index(), 1000);
  EXPECT_DOUBLE_EQ(sim->world().time(), 1.0);
  EXPECT_THROW(sim->world().step(-1), std::invalid_argument);
}

TEST(World, RejectsBadTimeStep) {
  SimulatorOptions options;
  options.time_step = 0.0;
  EXPECT_THROW(Simulator::create(options), std::invalid_argument);
}

TEST(Object, CheckedPoseRejectsNonRigidMatrices) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  EXPECT_NO_THROW(checked_pose(m));
  m(0, 0) = 2;  // scale
  EXPECT_THROW(checked_pose(m), std::invalid_argument);
  m = Eigen::Matrix4d::Identity();
  m(0, 0) = -1;  // reflection
  EXPECT_THROW(checked_pose(m), std::invalid_argument);
  m = Eigen::Matrix4d::Identity();
  m(3, 0) = 1;
  EXPECT_THROW(checked_pose(m), std::invalid_argument);
}

}  // namespace
}  // namespace ambfplus
