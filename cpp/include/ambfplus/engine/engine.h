#pragma once

// The engine: the layer above every area that puts a simulator together. `scene` is the ground
// floor (simulator, world, models, objects, names, and the staged World::step that runs whatever
// systems a world holds); physics, haptics, render and plugin each build systems on it; this
// layer decides which systems a world gets, in what order, and owns the loop that steps a world
// in real time (engine/realtime.h). Nothing below it includes it.

#include <memory>

#include "ambfplus/export.h"
#include "ambfplus/scene/simulator.h"

namespace ambfplus::engine {

/// Adds the engine's systems to a world that has only the scene's own, in the order objects are
/// announced to them: physics first (it may refuse an object), then input devices, drills, drill
/// sounds and the renderer, plugins last (they hear of an object once everything else has taken
/// it).
AMBFPLUS_API void install_systems(World& world);

/// A simulator whose world has the engine's systems: what ambfplus.Simulator is in Python.
/// Throws ArgumentError for bad options.
AMBFPLUS_API std::shared_ptr<Simulator> create_simulator(const SimulatorOptions& options = {});

}  // namespace ambfplus::engine
