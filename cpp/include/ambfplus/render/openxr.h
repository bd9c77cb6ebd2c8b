#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/capture/frame.h"
#include "ambfplus/export.h"

namespace ambfplus {

class Camera;

/// One eye of a frame, as the OpenXR runtime asks for it to be drawn.
struct AMBFPLUS_API XrEye {
  /// Head-start from eye: the pose in the session's LOCAL reference space (its origin and axes
  /// are the head's when the session began), in the OpenCV frame (x right, y down, z forward).
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  /// The eye's field of view as OpenXR gives it: angles left, right, up, down in radians
  /// (left and down are negative for a view centred on its axis).
  std::array<double, 4> fov{};
  int width = 0;   ///< the runtime's swapchain image for this eye, pixels
  int height = 0;  ///<
};

/// True when the engine was built with OpenXR's headers (the loader is found at run time).
AMBFPLUS_API bool openxr_built();

/// A session with the OpenXR runtime's head-mounted display (through the Khronos loader,
/// libopenxr_loader.so.1, opened at run time). The engine's EGL context is given to the runtime
/// (XR_MNDX_egl_enable); each eye's camera renders off screen as a capture does and is copied
/// into the runtime's swapchain image for that eye.
///
/// Per frame: poll_events(); then, while running(), wait_frame() gives the eyes (pose and field
/// of view at the frame's predicted display time), the caller places a camera per eye, and
/// end_frame(cameras) renders and submits them. Throws RenderError naming the call and the
/// runtime's result when the loader, a runtime or a head-mounted display is missing.
class AMBFPLUS_API OpenXrSession {
 public:
  explicit OpenXrSession(const std::string& application = "ambfplus");
  ~OpenXrSession();
  OpenXrSession(const OpenXrSession&) = delete;
  OpenXrSession& operator=(const OpenXrSession&) = delete;

  /// The runtime's name and version, e.g. "Monado 21.0.0".
  const std::string& runtime() const;
  /// The head-mounted display's name as the runtime gives it.
  const std::string& system() const;
  /// Each eye's recommended image size (the swapchains' size).
  std::vector<std::array<int, 2>> eye_sizes() const;

  /// The session's state, as OpenXR names it without its prefix: "idle", "ready",
  /// "synchronized", "visible", "focused", "stopping", "loss_pending", "exiting".
  std::string state() const;
  /// Between the runtime's "ready" and "stopping": frames are expected.
  bool running() const;
  /// The runtime ended the session ("exiting" or "loss_pending"): no more frames.
  bool ended() const;
  /// Frames submitted so far.
  long frames() const;

  /// Handles the runtime's queued events: begins the session when it is ready, ends it when
  /// it stops.
  void poll_events();
  /// Waits for the runtime's next frame and begins it; the eyes to draw (empty when the runtime
  /// shows nothing now). end_frame() must follow. Throws if the session is not running.
  std::vector<XrEye> wait_frame();
  /// Renders cameras[i] for eye i, copies each into its swapchain image (stretched to fill it)
  /// and ends the frame with a projection layer of those eyes. The frames' metadata, empty when
  /// wait_frame() gave no eyes.
  std::vector<Frame> end_frame(const std::vector<const Camera*>& cameras);
  /// Asks the runtime to stop the session (it then goes through "stopping" to "exiting").
  void request_exit();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ambfplus
