#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "ambfplus/engine/engine.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/system.h"
#include "ambfplus/scene/world.h"

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
  auto sim = engine::create_simulator();
  World& world = sim->world();
  world.default_model().add_body(sphere("a"));
  Model& other = world.add_model("other");
  EXPECT_THROW(other.add_body(sphere("a")), ArgumentError);
  CameraSpec camera;
  camera.name = "a";
  EXPECT_THROW(other.add_camera(camera), ArgumentError);
  EXPECT_EQ(world.objects().size(), 1u);
}

TEST(World, IdsAreStableAndNotReusedAfterAFailedAdd) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  const int a = world.default_model().add_body(sphere("a")).id();
  RigidBodySpec bad = sphere("bad");
  bad.shape.radius = -1;
  EXPECT_THROW(world.default_model().add_body(bad), ArgumentError);
  EXPECT_EQ(world.find("bad"), nullptr);
  const int b = world.default_model().add_body(sphere("b")).id();
  EXPECT_EQ(a, 1);
  EXPECT_GT(b, a);
  EXPECT_EQ(world.find("a")->id(), a);
}

// A system that writes down what it hears, and refuses objects named "refused".
class Recorder : public System {
 public:
  explicit Recorder(std::vector<std::string>& log, unsigned stages) : log_(log), stages_(stages) {}
  const char* name() const override { return "recorder"; }
  unsigned stages() const override { return stages_; }
  void object_added(Object& o) override {
    if (o.name() == "refused") throw ArgumentError("refused");
    log_.push_back("added " + o.name());
  }
  void object_removed(Object& o) override { log_.push_back("removed " + o.name()); }
  void prepare(const StepContext& c) override {
    log_.push_back("prepare " + std::to_string(c.step));
  }
  void run(StepStage stage, const StepContext& c) override {
    log_.push_back(std::string(step_stage_name(stage)) + " " + std::to_string(c.step));
  }

 private:
  std::vector<std::string>& log_;
  unsigned stages_;
};

// A step prepares every system, advances the clock, then runs the stages in their stated
// order; an object a system refuses is not kept and the systems that took it let it go.
TEST(World, StepRunsSystemsStageByStageAndObjectsAreAnnounced) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  std::vector<std::string> log;
  world.add_system(std::make_unique<Recorder>(
      log, stage_bit(StepStage::kSensors) | stage_bit(StepStage::kDeviceInput)));
  world.step(1);
  EXPECT_EQ(log, (std::vector<std::string>{"prepare 1", "device input 1", "sensors 1"}));
  log.clear();
  world.default_model().add_body(sphere("kept"));
  EXPECT_THROW(world.default_model().add_body(sphere("refused")), ArgumentError);
  EXPECT_EQ(world.find("refused"), nullptr);
  EXPECT_EQ(world.objects().size(), 1u);
  EXPECT_EQ(log, (std::vector<std::string>{"added kept"}));
  Model& model = world.add_model("m");
  model.add_body(sphere("gone"));
  log.clear();
  world.remove_model(model);
  EXPECT_EQ(log, (std::vector<std::string>{"removed gone"}));
  std::vector<std::string> names;
  for (System* s : world.systems()) names.push_back(s->name());
  EXPECT_EQ(names,
            (std::vector<std::string>{"attachments", "step log", "physics", "devices", "drills",
                                      "training", "sound", "renderer", "plugins", "recorder"}));
}

// The scene alone is a world that steps: its own systems only, no physics, renderer or plugins.
TEST(World, SceneAloneHasOnlyItsOwnSystems) {
  auto sim = Simulator::create();
  World& world = sim->world();
  std::vector<std::string> names;
  for (System* s : world.systems()) names.push_back(s->name());
  EXPECT_EQ(names, (std::vector<std::string>{"attachments", "step log"}));
  RigidBody& body = world.default_model().add_body(sphere("a"));
  world.start_step_log({&body});
  world.step(3);
  const StepLog log = world.take_step_log();
  EXPECT_EQ(log.rows(), 3);
  ASSERT_EQ(log.columns().size(), 1u);
  EXPECT_EQ(log.columns()[0].name, "a.pose");
  EXPECT_THROW(engine::install_systems(world), StateError);
}

// A system adds its own step-log columns; one may drop the pose.
class Columns : public System {
 public:
  const char* name() const override { return "columns"; }
  unsigned stages() const override { return 0; }
  void add_step_log_columns(const Object& object, StepLogColumns& columns) const override {
    if (object.name() != "b") return;
    columns.drop_pose();
    columns.add("id", 1, [](const Object& o, std::vector<double>& out) { out.push_back(o.id()); });
  }
};

TEST(World, SystemsAddStepLogColumns) {
  auto sim = Simulator::create();
  World& world = sim->world();
  world.add_system(std::make_unique<Columns>());
  RigidBody& a = world.default_model().add_body(sphere("a"));
  RigidBody& b = world.default_model().add_body(sphere("b"));
  world.start_step_log({&a, &b});
  world.step(2);
  const StepLog log = world.take_step_log();
  ASSERT_EQ(log.columns().size(), 2u);
  EXPECT_EQ(log.columns()[0].name, "a.pose");
  EXPECT_EQ(log.columns()[1].name, "b.id");
  EXPECT_EQ(log.columns()[1].values, (std::vector<double>{2.0, 2.0}));
  StepLogColumns bad(a);
  EXPECT_THROW(bad.add("x", 0, [](const Object&, std::vector<double>&) {}), ArgumentError);
}

// AMBF's lookup, in one function for Python and plugins alike.
TEST(Names, ResolveByAmbfRules) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBody& base = world.default_model().add_body(sphere("base"));
  base.set_name_space("/ambf/env/");
  base.set_identifier("BODY base");
  RigidBody& link = world.default_model().add_body(sphere("link"));
  link.set_name_space("/ambf/env/");
  JointSpec spec;
  spec.name = "base-link";
  spec.parent = &base;
  spec.child = &link;
  Joint& joint = world.default_model().add_joint(spec);
  joint.set_name_space("/ambf/env/");

  // An exact name, a qualified name, an identifier, namespace + identifier.
  EXPECT_EQ(&resolve_name(world, "base"), &base);
  EXPECT_EQ(&resolve_name(world, "/ambf/env/link"), &link);
  EXPECT_EQ(&resolve_name(world, "BODY base"), &base);
  EXPECT_EQ(&resolve_name(world, "/ambf/env/BODY base"), &base);
  // A part of a name: "base" is in the joint's name too, but an exact name wins; "lin" is in
  // the link's and the joint's, and joints only count when nothing else does.
  EXPECT_EQ(&resolve_name(world, "lin"), &link);
  EXPECT_EQ(name_candidates(world, "lin", ObjectKind::kJoint), (std::vector<Object*>{&joint}));
  EXPECT_EQ(&resolve_name(world, "base-", ObjectKind::kJoint), &joint);
  // A kind rules objects out; nothing, or several alike, is NotFound naming them.
  EXPECT_THROW(resolve_name(world, "base", ObjectKind::kCamera), NotFound);
  EXPECT_THROW(resolve_name(world, "nothing"), NotFound);
  try {
    resolve_name(world, "/ambf/env/");
    FAIL() << "an ambiguous name resolved";
  } catch (const NotFound& e) {
    EXPECT_NE(std::string(e.what()).find("ambiguous"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("(base, link"), std::string::npos) << e.what();
  }
  // Two namespaces may each have a "tool": each keeps its name and is found by its full name
  // or its key; the bare name is ambiguous, naming both keys.
  Model& arms = world.add_model("arms");
  arms.set_object_name_space("/ambf/env/psm1/");
  RigidBody& tool1 = arms.add_body(sphere("tool"));
  arms.set_object_name_space("/ambf/env/psm2/");
  RigidBody& tool2 = arms.add_body(sphere("tool"));
  EXPECT_EQ(tool1.name(), "tool");
  EXPECT_EQ(tool2.key(), "psm2/tool");
  EXPECT_EQ(world.find("psm1/tool"), &tool1);
  EXPECT_EQ(&resolve_name(world, "/ambf/env/psm2/tool"), &tool2);
  EXPECT_EQ(&resolve_name(world, "psm1/tool"), &tool1);
  try {
    resolve_name(world, "tool");
    FAIL() << "an ambiguous bare name resolved";
  } catch (const NotFound& e) {
    EXPECT_NE(std::string(e.what()).find("psm1/tool, psm2/tool"), std::string::npos) << e.what();
  }
  // A key taken in the same namespace is refused; moving into a taken key too.
  EXPECT_THROW(arms.add_body(sphere("tool")), ArgumentError);
  EXPECT_THROW(tool1.set_name_space("/ambf/env/psm2/"), ArgumentError);
  EXPECT_EQ(tool1.key(), "psm1/tool");
  EXPECT_EQ(name_key("/ambf/env/", "l1"), "l1");
  EXPECT_EQ(name_key("", "l1"), "l1");
  EXPECT_EQ(name_key("/other/ns", "l1"), "other/ns/l1");
  EXPECT_EQ(parse_object_kind("input device"), ObjectKind::kInputDevice);
  EXPECT_THROW(parse_object_kind("widget"), ArgumentError);
}

TEST(World, ClockCountsFixedStepsWithoutDrift) {
  SimulatorOptions options;
  options.time_step = 0.001;
  auto sim = engine::create_simulator(options);
  for (int i = 0; i < 1000; ++i) sim->step();
  EXPECT_EQ(sim->world().step_index(), 1000);
  EXPECT_DOUBLE_EQ(sim->world().time(), 1.0);
  EXPECT_THROW(sim->world().step(-1), ArgumentError);
}

TEST(World, RejectsBadTimeStep) {
  SimulatorOptions options;
  options.time_step = 0.0;
  EXPECT_THROW(engine::create_simulator(options), ArgumentError);
}

TEST(Object, CheckedPoseRejectsNonRigidMatrices) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  EXPECT_NO_THROW(checked_pose(m));
  m(0, 0) = 2;  // scale
  EXPECT_THROW(checked_pose(m), ArgumentError);
  m = Eigen::Matrix4d::Identity();
  m(0, 0) = -1;  // reflection
  EXPECT_THROW(checked_pose(m), ArgumentError);
  m = Eigen::Matrix4d::Identity();
  m(3, 0) = 1;
  EXPECT_THROW(checked_pose(m), ArgumentError);
}

TEST(Object, CheckedPoseBoundsThePositionAndNamesWhoGaveIt) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(1, 3) = -kMaxPosition;
  EXPECT_NO_THROW(checked_pose(m, "body 'a'"));
  m(1, 3) = -2 * kMaxPosition;
  try {
    checked_pose(m, "body 'a'");
    FAIL() << "a position beyond kMaxPosition was accepted";
  } catch (const ArgumentError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("body 'a': position (", 0), 0u) << e.what();
  }
  m(1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(checked_pose(m), ArgumentError);
}

TEST(World, RidersFollowWhenTheirParentIsPutOnABody) {
  // A stereo camera's eyes ride on the camera; the camera is then put on a body (an AMBF world
  // file's camera whose parent comes from a later model): the eyes move with it at once, not
  // at the next step, so a capture before any step sees from the right place.
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBodySpec frame = sphere("frame");
  frame.pose(0, 3) = 1.0;
  frame.pose(2, 3) = 0.5;
  Object& body = world.default_model().add_body(frame);
  CameraSpec spec;
  spec.name = "main";
  Object& camera = world.default_model().add_camera(spec);
  spec.name = "main_left";
  Object& eye = world.default_model().add_camera(spec);
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() = Eigen::Vector3d(-0.025, 0.0, 0.0);
  eye.attach_to(&camera, offset);
  EXPECT_TRUE(eye.pose().translation().isApprox(Eigen::Vector3d(-0.025, 0.0, 0.0)));
  camera.attach_to(&body, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(camera.pose().translation().isApprox(Eigen::Vector3d(1.0, 0.0, 0.5)));
  EXPECT_TRUE(eye.pose().translation().isApprox(Eigen::Vector3d(0.975, 0.0, 0.5)))
      << eye.pose().translation().transpose();
}

}  // namespace
}  // namespace ambfplus
