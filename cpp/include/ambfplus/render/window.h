#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "ambfplus/capture/frame.h"
#include "ambfplus/export.h"

namespace ambfplus {

class Camera;

/// Makes the engine's OpenGL context live on this X11 display (a Display*, e.g. GLFW's
/// glfwGetX11Display()), so that windows of that display can show cameras. Call it before the
/// process renders anything; throws RenderError if it already has.
AMBFPLUS_API void use_x11_display(void* display);

/// A head-mounted display's lens distortion, undone on each view a window shows (the PanoTools
/// model OpenHMD describes displays with): a window pixel at distance r from its view's lens
/// centre (r in units of `radius`) shows the camera's image at r (a r^3 + b r^2 + c r + d) from
/// the centre, each colour channel scaled by its `aberration`.
struct AMBFPLUS_API LensDistortion {
  std::array<float, 4> k{0, 0, 0, 1};  ///< a, b, c, d
  std::array<float, 3> aberration{1, 1, 1};
  /// Each view's lens centre, as fractions of its viewport (x from the left, y from the bottom).
  std::vector<std::array<float, 2>> centres;
  float radius = 0.5f;  ///< the unit of r, as a fraction of the viewport's width
  float aspect = 1.0f;  ///< the viewport's physical width / height
};

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
  /// rendered: show the images the cameras last rendered for a display (e.g. an OpenXR
  /// session's end_frame) without rendering again; their frames then carry only the names.
  std::vector<Frame> present(const std::vector<const Camera*>& cameras, int width, int height,
                             const std::uint8_t* overlay = nullptr, bool rendered = false);
  /// Undoes a lens's distortion on every view from now on (std::nullopt: plain images).
  void set_lens(std::optional<LensDistortion> lens);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ambfplus
