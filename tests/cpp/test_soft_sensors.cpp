#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "ambfplus/engine/engine.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/simulator.h"

namespace ambfplus {
namespace {

// A tetrahedron as an OBJ file in the temporary directory.
std::string tetrahedron_file() {
  const std::string path = ::testing::TempDir() + "ambfplus_tetrahedron.obj";
  std::ofstream out(path);
  out << "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n"
         "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  return path;
}

RigidBodySpec box(const std::string& name, double mass, double x) {
  RigidBodySpec spec;
  spec.name = name;
  spec.shape.kind = Shape::Kind::kBox;
  spec.shape.size = Eigen::Vector3d::Constant(0.02);
  spec.dynamics.mass = mass;
  spec.pose(0, 3) = x;
  return spec;
}

TEST(SoftSensors, RemovingAModelReleasesWhatItsBodiesWereHeldBy) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBody& hand = world.default_model().add_body(box("hand", 0, 0));
  ConstraintActuatorSpec grip;
  grip.name = "grip";
  grip.parent = &hand;
  ConstraintActuator& actuator = world.default_model().add_actuator(grip);
  ProximitySensorSpec eye;
  eye.name = "eye";
  eye.parent = &hand;
  eye.rays.push_back({});
  ProximitySensor& sensor = world.default_model().add_sensor(eye);

  Model& other = world.add_model("other");
  RigidBody& held = other.add_body(box("held", 0.1, 0.1));
  SoftBodySpec soft;
  soft.name = "soft";
  soft.mesh = tetrahedron_file();
  soft.pose(2, 3) = 1.0;
  SoftBody& jelly = other.add_soft_body(soft);
  EXPECT_EQ(jelly.node_count(), 4u);
  EXPECT_EQ(jelly.triangles().size(), 12u);
  actuator.actuate(held);
  world.step(10);
  ASSERT_TRUE(sensor.hits()[0].triggered);
  EXPECT_EQ(sensor.hits()[0].body, &held);

  world.remove_model(other);
  EXPECT_FALSE(actuator.is_actuated());
  world.step(10);  // Bullet no longer refers to the removed body or soft body
  EXPECT_FALSE(sensor.hits()[0].triggered);
  EXPECT_TRUE(world.objects_of_kind<SoftBody>().empty());
  std::remove(soft.mesh.c_str());
}

TEST(SoftSensors, AWorldWithHoldsAndSoftBodiesGoesAwayCleanly) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBody& hand = world.default_model().add_body(box("hand", 0, 0));
  RigidBody& held = world.default_model().add_body(box("held", 0.1, 0.1));
  ConstraintActuatorSpec grip;
  grip.name = "grip";
  grip.parent = &hand;
  grip.hold = ActuatorHold::kPoint;
  world.default_model().add_actuator(grip).actuate(held);
  SoftBodySpec soft;
  soft.name = "soft";
  soft.mesh = tetrahedron_file();
  world.default_model().add_soft_body(soft);
  world.step(10);
  sim.reset();  // constraints and soft bodies leave Bullet before their bodies are deleted
  std::remove(soft.mesh.c_str());
}

TEST(SoftSensors, ConfigKeysAreAmbfs) {
  SoftBodyConfig c;
  EXPECT_TRUE(set_soft_body_config(c, "kSR_SPLT_CL", 0.25));
  EXPECT_DOUBLE_EQ(c.cluster_rigid_impulse_split, 0.25);
  EXPECT_TRUE(set_soft_body_config(c, "bending constraint", 2));
  EXPECT_TRUE(set_soft_body_config(c, "bending_constraint", 3));
  EXPECT_EQ(*c.bending_constraint, 3);
  EXPECT_FALSE(set_soft_body_config(c, "fixed nodes", 1));  // a list, not a number
  EXPECT_FALSE(set_soft_body_config(c, "kLSTX", 1));
  EXPECT_THROW(set_soft_body_config(c, "piterations", 1.5), ArgumentError);
}

}  // namespace
}  // namespace ambfplus
