#pragma once

// The render system's public face: what captures (and the render area's windows) ask of a
// world's renderer.

#include <memory>

#include "ambfplus/capture/capture.h"
#include "ambfplus/capture/frame.h"
#include "ambfplus/export.h"
#include "ambfplus/scene/system.h"

namespace ambfplus {

class Camera;
class World;

namespace render {

/// Draws a world for its cameras; holds the world's GPU resources, each released when no
/// object uses it any more. A render copies what it draws (and the poses asked for) out of the
/// world under its state lock and draws after releasing it; it never runs in a step's stages.
class AMBFPLUS_API Renderer : public System {
 public:
  /// Renders the camera's view into the buffers given (the GPU-drawn passes; null ones are
  /// skipped) and fills frame's time, step, camera, intrinsics, pose and the poses asked for,
  /// all of one simulation step. Throws RenderError when the GPU cannot.
  virtual void render(const Camera& camera, const CaptureBuffers& buffers, const PoseRequest& poses,
                      Frame& frame) = 0;
};

/// The renderer of a world (nothing touches the GPU before its first render).
AMBFPLUS_API std::unique_ptr<Renderer> make_renderer(World& world);
/// A world's renderer (engine::install_systems adds it). Throws StateError for a world without
/// one.
AMBFPLUS_API Renderer& renderer_of(const World& world);

}  // namespace render
}  // namespace ambfplus
