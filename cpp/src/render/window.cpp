#include "ambfplus/render/window.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"
#include "render/scene_renderer.h"

namespace ambfplus {

void use_x11_display(void* display) { render::Context::use_x11_display(display); }

namespace {

// Copies the view's image into a texture (the lens pass samples it anywhere), then draws the
// viewport through the lens.
void draw_through_lens(const render::RenderTarget& target, const LensDistortion& lens, int view,
                       std::array<GLuint, 3>& texture, GLuint vao, int x, int width, int height) {
  if (texture[0] == 0 || static_cast<int>(texture[1]) != target.width ||
      static_cast<int>(texture[2]) != target.height) {
    // Storage is immutable: a new size takes a new texture.
    if (texture[0] != 0) glDeleteTextures(1, &texture[0]);
    glGenTextures(1, &texture[0]);
    glBindTexture(GL_TEXTURE_2D, texture[0]);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, target.width, target.height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    texture[1] = static_cast<GLuint>(target.width);
    texture[2] = static_cast<GLuint>(target.height);
  }
  glCopyImageSubData(target.textures[0], GL_TEXTURE_2D, 0, 0, 0, 0, texture[0], GL_TEXTURE_2D, 0, 0,
                     0, 0, target.width, target.height, 1);
  std::array<float, 2> centre{0.5f, 0.5f};
  if (!lens.centres.empty()) {
    centre = lens.centres[std::min(static_cast<std::size_t>(view), lens.centres.size() - 1)];
  }
  render::Program& program = render::Context::get().program("overlay.vert", "lens.frag");
  program.use();
  glUniform1i(program.uniform("u_image"), 0);
  glUniform4f(program.uniform("u_k"), lens.k[0], lens.k[1], lens.k[2], lens.k[3]);
  glUniform3f(program.uniform("u_aberration"), lens.aberration[0], lens.aberration[1],
              lens.aberration[2]);
  glUniform2f(program.uniform("u_centre"), centre[0], centre[1]);
  glUniform1f(program.uniform("u_radius"), lens.radius);
  glUniform1f(program.uniform("u_aspect"), lens.aspect);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture[0]);
  glViewport(x, 0, width, height);
  glBindVertexArray(vao);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindVertexArray(0);
}

}  // namespace

struct Window::State {
  EGLSurface surface = EGL_NO_SURFACE;
  GLuint overlay = 0;  // texture
  GLuint vao = 0;      // empty: the quad comes from vertex ids
  int overlay_width = 0, overlay_height = 0;
  std::optional<LensDistortion> lens;
  // A texture per view holding its image for the lens pass: texture, width, height.
  std::vector<std::array<GLuint, 3>> views;
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
    for (const auto& v : state_->views) glDeleteTextures(1, &v[0]);
    glDeleteTextures(1, &state_->overlay);
    glDeleteVertexArrays(1, &state_->vao);
    eglDestroySurface(render::Context::get().display(), state_->surface);
  } catch (const Error&) {
    // The context is gone with the process's display; so are these.
  }
}

std::vector<Frame> Window::present(const std::vector<const Camera*>& cameras, int width, int height,
                                   const std::uint8_t* overlay, bool rendered) {
  if (width <= 0 || height <= 0) {
    throw ArgumentError("a window's size must be positive, got " + std::to_string(width) + "x" +
                        std::to_string(height));
  }
  std::vector<Frame> frames(cameras.size());
  std::vector<const render::RenderTarget*> targets;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    render::SceneRenderer& renderer =
        static_cast<render::SceneRenderer&>(render::renderer_of(cameras[i]->world()));
    if (!rendered) {
      targets.push_back(&renderer.render_to_target(*cameras[i], kPassRgb, frames[i]));
      continue;
    }
    const render::RenderTarget* last = renderer.last_target(*cameras[i]);
    if (last == nullptr) {
      throw ArgumentError("camera '" + cameras[i]->name() +
                          "' has not rendered for a display yet (rendered=True)");
    }
    frames[i].camera = cameras[i]->name();
    targets.push_back(last);
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
    if (s.lens) {
      while (static_cast<int>(s.views.size()) <= i) s.views.push_back({0, 0, 0});
      draw_through_lens(t, *s.lens, i, s.views[static_cast<std::size_t>(i)], s.vao, x0, x1 - x0,
                        height);
      continue;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBlitFramebuffer(0, 0, t.width, t.height, x0, height, x1, 0, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
  glViewport(0, 0, width, height);
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

void Window::set_lens(std::optional<LensDistortion> lens) {
  if (lens) {
    const auto finite = [](float v) { return std::isfinite(v); };
    const bool ok = std::all_of(lens->k.begin(), lens->k.end(), finite) &&
                    std::all_of(lens->aberration.begin(), lens->aberration.end(), finite) &&
                    finite(lens->radius) && finite(lens->aspect) && lens->radius > 0 &&
                    lens->aspect > 0;
    if (!ok) {
      throw ArgumentError(
          "a lens needs finite coefficients and aberrations and a positive radius and aspect");
    }
  }
  state_->lens = std::move(lens);
}

}  // namespace ambfplus
