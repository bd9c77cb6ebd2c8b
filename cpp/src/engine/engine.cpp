#include "ambfplus/engine/engine.h"

#include "ambfplus/audio/systems.h"
#include "ambfplus/errors.h"
#include "ambfplus/haptics/systems.h"
#include "ambfplus/physics/physics.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/render/renderer.h"
#include "ambfplus/scene/world.h"
#include "ambfplus/training/live_metrics.h"

namespace ambfplus::engine {

void install_systems(World& world) {
  if (world.find_system<physics::Physics>() != nullptr || !world.objects().empty()) {
    throw StateError("world '" + world.name() +
                     "': the engine's systems go into a new world, once");
  }
  world.add_system(physics::make_physics(world));
  world.add_system(haptics::make_device_system());
  world.add_system(haptics::make_drill_system());
  world.add_system(training::make_training_system());
  world.add_system(audio::make_sound_system());
  world.add_system(render::make_renderer(world));
  world.add_system(std::make_unique<PluginRegistry>(world));
}

std::shared_ptr<Simulator> create_simulator(const SimulatorOptions& options) {
  std::shared_ptr<Simulator> simulator = Simulator::create(options);
  install_systems(simulator->world());
  return simulator;
}

}  // namespace ambfplus::engine
