// The thread-safety contract under stress: while a RealTimeLoop steps a world, four threads add
// and remove bodies, load and remove model files, edit and reset the volume's labels and capture,
// all through the engine's plain API (which takes the world's lock itself). Run for
// AMBFPLUS_STRESS_SECONDS (2 s by default; CI's sanitizer builds run it for 60 s under
// AddressSanitizer and ThreadSanitizer, .ci/sanitizers).

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "ambfplus/adf/adf.h"
#include "ambfplus/capture/capture.h"
#include "ambfplus/engine/engine.h"
#include "ambfplus/engine/realtime.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/volume/phantom.h"

namespace ambfplus {
namespace {

namespace fs = std::filesystem;

double stress_seconds() {
  const char* text = std::getenv("AMBFPLUS_STRESS_SECONDS");
  return text != nullptr ? std::atof(text) : 2.0;
}

TEST(Concurrency, FourThreadsChangeAWorldWhileALoopStepsIt) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  VolumeSpec volume;
  volume.name = "anatomy";
  volume.data = make_temporal_bone_phantom(32, 0);
  Volume& anatomy = world.default_model().add_volume(volume);
  CameraSpec camera;
  camera.name = "cam";
  camera.width = 48;
  camera.height = 32;
  Camera& cam = world.default_model().add_camera(camera);
  cam.look_at({0, 0, 0.12}, {0, 0, 0}, {0, 1, 0});
  const fs::path dir = fs::temp_directory_path() / "ambfplus_concurrency";
  fs::create_directories(dir);
  const fs::path model_file = dir / "cube.yaml";
  std::ofstream(model_file) << "bodies: [BODY cube]\nBODY cube:\n  name: cube\n  mass: 0.1\n"
                               "  collision shape: BOX\n"
                               "  collision geometry: {x: 0.002, y: 0.002, z: 0.002}\n"
                               "  location: {position: {x: 0.05, y: 0, z: 0.05},\n"
                               "             orientation: {r: 0, p: 0, y: 0}}\n";

  RealTimeOptions options;
  options.fifo_priority = 0;
  RealTimeLoop loop(world, options);
  loop.start();
  std::atomic<bool> stop{false};
  std::atomic<int> failures{0};
  std::vector<std::atomic<long>> done(4);
  auto run = [&](int slot, auto&& work) {
    return std::thread([&, slot, work] {
      long i = 0;
      while (!stop) {
        try {
          work(i);
        } catch (const Error&) {
          ++failures;  // a typed refusal would be a bug here too: nothing should be refused
        }
        done[slot] = ++i;
      }
    });
  };
  std::vector<std::thread> threads;
  threads.push_back(run(0, [&](long i) {  // add a model of bodies, then remove it
    Model& model = world.add_model("added" + std::to_string(i));
    for (int b = 0; b < 3; ++b) {
      RigidBodySpec ball;
      ball.name = "ball" + std::to_string(i) + "_" + std::to_string(b);
      ball.shape.kind = Shape::Kind::kSphere;
      ball.shape.radius = 0.001;
      ball.dynamics.mass = 0.01;
      model.add_body(ball);
    }
    world.remove_model(model);
  }));
  threads.push_back(run(1, [&](long) {  // load a model file, then remove it
    world.remove_model(load_model_file(world, model_file.string()));
  }));
  threads.push_back(run(2, [&](long i) {  // edit the labels, and now and then reset them
    const double a = 0.3 * static_cast<double>(i);
    anatomy.data()->remove_sphere({0.01 * std::sin(a), 0.01 * std::cos(a), 0.02}, 0.003, false);
    if (i % 5 == 4) anatomy.data()->reset();
  }));
  threads.push_back(run(3, [&](long) { capture_frame(cam); }));
  std::this_thread::sleep_for(std::chrono::duration<double>(stress_seconds()));
  stop = true;
  for (std::thread& t : threads) t.join();
  loop.stop();
  fs::remove_all(dir);
  EXPECT_EQ(failures.load(), 0);
  for (int slot = 0; slot < 4; ++slot) EXPECT_GT(done[slot].load(), 0) << "thread " << slot;
  EXPECT_GT(loop.stats().steps, 0);
  EXPECT_EQ(world.models().size(), 1u);  // every added model was removed
}

}  // namespace
}  // namespace ambfplus
