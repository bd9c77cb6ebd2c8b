#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "ambfplus/capture/frame.h"
#include "ambfplus/export.h"

namespace ambfplus {

class Camera;

/// Makes the engine's OpenGL context live on this X11 display (a Display*, e.g. GLFW's
/// glfwGetX11Display()), so that windows of that display can show cameras. Call it before the
/// process renders anything; throws RenderError if it already has.
AMBFPLUS_API void use_x11_display(void* display);

/// A window showing cameras: an EGL window surface on an X11 window of the display given to
/// use_x11_display (GLFW's glfwGetX11Window(), created without a client API). Cameras render
/// off screen exactly as headless captures do; present() copies their colour images into the
/// window (no readback) and shows it.
class AMBFPLUS_API Window {
 public:
  explicit Window(unsigned long x11_window);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// Renders each camera and shows them side by side, left to right, filling a window of
  /// width x height pixels; overlay (RGBA, width x height, row 0 at the top; may be null) is
  /// blended over them. Returns the frames' metadata (time, step, pose of what is shown).
  std::vector<Frame> present(const std::vector<const Camera*>& cameras, int width, int height,
                             const std::uint8_t* overlay = nullptr);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ambfplus
