#include "ambfplus/render/window.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"
#include "render/scene_renderer.h"

namespace ambfplus {

void use_x11_display(void* display) { render::Context::use_x11_display(display); }

struct Window::State {
  EGLSurface surface = EGL_NO_SURFACE;
  GLuint overlay = 0;  // texture
  GLuint vao = 0;      // empty: the quad comes from vertex ids
  int overlay_width = 0, overlay_height = 0;
};

Window::Window(unsigned long x11_window) : state_(std::make_unique<State>()) {
  render::Context& context = render::Context::get();
  if (context.info().platform != "x11") {
    throw RenderError(
        "a window needs use_x11_display() before the process first renders (its "
        "context is on the " +
        context.info().platform + " platform)");
  }
  render::Context::Scope scope;
  Window::State& s = *state_;
  EGLNativeWindowType native = x11_window;
  s.surface = eglCreateWindowSurface(context.display(), context.config(), native, nullptr);
  if (s.surface == EGL_NO_SURFACE) {
    throw RenderError("cannot make an EGL surface of X11 window " + std::to_string(x11_window) +
                      ": " + render::Context::error_name());
  }
  glGenTextures(1, &s.overlay);
  glBindTexture(GL_TEXTURE_2D, s.overlay);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glGenVertexArrays(1, &s.vao);
  render::check_gl("creating a window's overlay");
}

Window::~Window() {
  if (!render::Context::exists()) return;
  try {
    render::Context::Scope scope;
    glDeleteTextures(1, &state_->overlay);
    glDeleteVertexArrays(1, &state_->vao);
    eglDestroySurface(render::Context::get().display(), state_->surface);
  } catch (const Error&) {
    // The context is gone with the process's display; so are these.
  }
}

std::vector<Frame> Window::present(const std::vector<const Camera*>& cameras, int width, int height,
                                   const std::uint8_t* overlay) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("a window's size must be positive, got " + std::to_string(width) +
                                "x" + std::to_string(height));
  }
  std::vector<Frame> frames(cameras.size());
  std::vector<const render::RenderTarget*> targets;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    targets.push_back(
        &cameras[i]->world().renderer().render_to_target(*cameras[i], kPassRgb, frames[i]));
  }
  render::Context& context = render::Context::get();
  render::Context::Scope scope;
  State& s = *state_;
  context.make_current(s.surface);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDrawBuffer(GL_BACK);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  // Each camera fills its share of the window; its image's row 0 (its target's first row) goes
  // to the window's top.
  const int n = static_cast<int>(targets.size());
  for (int i = 0; i < n; ++i) {
    const render::RenderTarget& t = *targets[i];
    const int x0 = width * i / n, x1 = width * (i + 1) / n;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBlitFramebuffer(0, 0, t.width, t.height, x0, height, x1, 0, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
  if (overlay != nullptr) {
    glBindTexture(GL_TEXTURE_2D, s.overlay);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (s.overlay_width != width || s.overlay_height != height) {
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                   overlay);
      s.overlay_width = width;
      s.overlay_height = height;
    } else {
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, overlay);
    }
    render::Program& program = context.program("overlay.vert", "overlay.frag");
    program.use();
    glUniform1i(program.uniform("u_overlay"), 0);
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindVertexArray(s.vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
  }
  render::check_gl("presenting a window");
  if (!eglSwapBuffers(context.display(), s.surface)) {
    throw RenderError("eglSwapBuffers failed: " + render::Context::error_name());
  }
  context.make_current(EGL_NO_SURFACE);
  return frames;
}

}  // namespace ambfplus
