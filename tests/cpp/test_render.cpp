#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "ambfplus/engine/engine.h"
#include "ambfplus/errors.h"
#include "ambfplus/render/gl_info.h"
#include "ambfplus/scene/simulator.h"
#include "render/egl_context.h"
#include "render/scene_renderer.h"

namespace ambfplus {
namespace {

TEST(Render, ContextReportsOpenGL45) {
  const GlInfo info = gl_info();
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_NE(info.version.find("4."), std::string::npos) << info.version;
  EXPECT_TRUE(info.profile == "compatibility" || info.profile == "core");
}

// Removing a model frees the GL objects only it used, and the renderer (with the resources of
// what stays) carries on: it is not thrown away and rebuilt.
TEST(Render, RemovingAModelReleasesItsResourcesOnly) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBodySpec box;
  box.name = "box";
  box.dynamics.mass = 0;
  world.default_model().add_body(box);
  CameraSpec spec;
  spec.name = "cam";
  spec.width = 32;
  spec.height = 24;
  Camera& cam = world.default_model().add_camera(spec);
  cam.look_at({0, 0, 3}, {0, 0, 0}, {0, 1, 0});
  Model& model = world.add_model("extra");
  RigidBodySpec ball;
  ball.name = "ball";
  ball.shape.kind = Shape::Kind::kSphere;
  ball.dynamics.mass = 0;
  model.add_body(ball);
  spec.name = "cam2";
  model.add_camera(spec).look_at({0, 3, 0}, {0, 0, 0});
  capture_frame(cam);
  capture_frame(static_cast<Camera&>(*world.find("cam2")));
  auto& renderer = static_cast<render::SceneRenderer&>(render::renderer_of(world));
  EXPECT_EQ(renderer.resource_counts(), (std::array<std::size_t, 4>{2, 0, 2, 0}));
  world.remove_model(model);
  const Frame frame = capture_frame(cam);
  EXPECT_EQ(&render::renderer_of(world), &renderer);
  EXPECT_EQ(renderer.resource_counts(), (std::array<std::size_t, 4>{1, 0, 1, 0}));
  EXPECT_NEAR(frame.depth.data()[12 * 32 + 16], 2.5f, 1e-5f);
}

// A box face parallel to the image plane has one depth everywhere it covers, and the capture
// stamps the clock and the camera's geometry.
TEST(Render, FrontalFaceHasExactDepthAndFrameCarriesTime) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RigidBodySpec box;
  box.name = "box";
  box.shape.size = {0.4, 0.4, 0.2};
  box.dynamics.mass = 0;  // static: it must not fall while the clock runs
  world.default_model().add_body(box);
  CameraSpec spec;
  spec.name = "cam";
  spec.width = 64;
  spec.height = 48;
  spec.near = 0.01;
  Camera& cam = world.default_model().add_camera(spec);
  cam.look_at({0, 0, 1.1}, {0, 0, 0}, {0, 1, 0});
  world.step(7);
  const Frame frame = capture_frame(cam);
  ASSERT_EQ(frame.depth.size(), 64u * 48u);
  EXPECT_EQ(frame.step, 7);
  EXPECT_DOUBLE_EQ(frame.time, 0.007);
  // The top face (z = 0.1) is 1.0 m away along the optical axis.
  const float centre = frame.depth.data()[24 * 64 + 32];
  EXPECT_NEAR(centre, 1.0f, 1e-5f);
  // Corners see nothing.
  EXPECT_EQ(frame.depth.data()[0], 0.0f);
  EXPECT_EQ(frame.rgb.data()[0], 0);
}

TEST(Render, MissingShaderFileIsAssetNotFound) {
  render::Context::Scope scope;
  EXPECT_THROW(render::Program("/nonexistent/a.vert", "/nonexistent/a.frag"), AssetNotFound);
}

TEST(Render, ShaderErrorsNameTheFileAndCarryTheLog) {
  const std::string dir = ::testing::TempDir();
  const std::string vert = dir + "/ok.vert", frag = dir + "/broken.frag";
  std::ofstream(vert) << "#version 450 core\nvoid main() { gl_Position = vec4(0); }\n";
  std::ofstream(frag) << "#version 450 core\nout vec4 c;\nvoid main() { c = undeclared; }\n";
  render::Context::Scope scope;
  try {
    render::Program program(vert, frag);
    FAIL() << "a broken shader compiled";
  } catch (const RenderError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(frag), std::string::npos) << message;
    EXPECT_NE(message.find("undeclared"), std::string::npos) << message;
  }
}

}  // namespace
// A driver that tears itself down before the engine's context at exit (NVIDIA's EGL library runs
// its own exit handler first) must not make the exit abort: the context then makes no GL call.
// Simulated here by terminating the display after a capture; the child process must exit 0.
TEST(RenderDeathTest, ExitAfterTheDriverWasTornDownIsClean) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        auto sim = engine::create_simulator();
        World& world = sim->world();
        RigidBodySpec box;
        box.name = "box";
        box.dynamics.mass = 0;
        world.default_model().add_body(box);
        CameraSpec spec;
        spec.name = "cam";
        spec.width = 32;
        spec.height = 24;
        Camera& cam = world.default_model().add_camera(spec);
        cam.look_at({0, 0, 3}, {0, 0, 0}, {0, 1, 0});
        capture_frame(cam);  // compiles the programs the context keeps until exit
        sim.reset();
        eglTerminate(render::Context::get().display());
        std::exit(0);
      },
      ::testing::ExitedWithCode(0), "");
}

// Supersampling picks a pixel whose neighbours (of the 8) differ in object, label, depth (over
// 1%) or colour (over 25 of 255 in a channel), and nothing else.
TEST(Supersampling, EdgesArePickedByTheExactPassesAndColourSteps) {
  const int w = 9, h = 7;
  render::EdgeInputs in;
  in.rgba.assign(w * h * 4, 100);
  in.depth.assign(w * h, 0.5f);
  in.label.assign(w * h, 3);
  in.instance.assign(w * h, 7);
  std::vector<std::uint8_t> mask(w * h, 9);
  auto marked = [&] {
    render::supersample_edges(in, w, h, mask.data());
    std::vector<std::pair<int, int>> out;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (mask[y * w + x] != 0) out.emplace_back(x, y);
    return out;
  };
  EXPECT_TRUE(marked().empty());
  const auto block = [](int cx, int cy) {
    std::vector<std::pair<int, int>> b;
    for (int y = cy - 1; y <= cy + 1; ++y)
      for (int x = cx - 1; x <= cx + 1; ++x) b.emplace_back(x, y);
    return b;
  };
  const int p = 3 * w + 4;  // (4, 3)
  in.label[p] = 4;
  EXPECT_EQ(marked(), block(4, 3));
  in.label[p] = 3;
  in.instance[p] = 8;
  EXPECT_EQ(marked(), block(4, 3));
  in.instance[p] = 7;
  in.depth[p] = 0.5f * 1.009f;
  EXPECT_TRUE(marked().empty());
  in.depth[p] = 0.5f * 1.011f;
  EXPECT_EQ(marked(), block(4, 3));
  in.depth[p] = 0.5f;
  in.rgba[p * 4 + 1] = 125;
  EXPECT_TRUE(marked().empty());
  in.rgba[p * 4 + 1] = 126;
  EXPECT_EQ(marked(), block(4, 3));
  // At a corner, only the pixels inside.
  in.rgba[p * 4 + 1] = 100;
  in.label[0] = 1;
  EXPECT_EQ(marked(), (std::vector<std::pair<int, int>>{{0, 0}, {1, 0}, {0, 1}, {1, 1}}));
}

}  // namespace ambfplus
