#pragma once

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <sys/types.h>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "ambfplus/render/gl_info.h"
#include "render/gl_program.h"

namespace ambfplus::render {

/// The process's one EGL display and OpenGL context, created on first use in the process that
/// uses it (never inherited through fork).
///
/// Device choice, in order: AMBFPLUS_EGL_DEVICE (an EGL device index) or AMBFPLUS_CUDA_DEVICE (a
/// CUDA ordinal, NVIDIA only) when set, failing if that device cannot be used; else the first EGL
/// device that gives an OpenGL 4.5 context; else Mesa's surfaceless platform.
class Context {
 public:
  /// The context, created on first call. Throws RenderError naming what is missing.
  static Context& get();

  ~Context();
  const GlInfo& info() const { return info_; }
  /// True once the context exists in this process (it is never destroyed before exit).
  static bool exists();
  /// Makes the context (when it is created) use this X11 Display* (GLFW's), so windows of that
  /// display can show cameras. Throws RenderError when the process already rendered.
  static void use_x11_display(void* display);

  EGLDisplay display() const { return display_; }
  EGLConfig config() const { return config_; }
  EGLContext context() const { return context_; }
  /// Within a Scope: draw and read through a window surface (eglSwapBuffers shows it).
  void make_current(EGLSurface surface);
  /// The name of the last EGL error.
  static std::string error_name();

  /// A program built from two files of shader_dir() with the given defines, compiled once per
  /// process. Needs a Scope.
  Program& program(const std::string& vertex_file, const std::string& fragment_file,
                   const std::string& defines = "");
  /// A program cached under key, made by make() on its first request (which may throw, caching
  /// nothing). Needs a Scope.
  Program& program(const std::string& key, const std::function<std::unique_ptr<Program>()>& make);

  /// Serialises GL work across threads and keeps the context current on this thread while alive.
  class Scope {
   public:
    Scope();
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    Context& context_;
  };

 private:
  Context();
  void make_current();
  void release();

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLConfig config_ = nullptr;
  pid_t pid_ = 0;
  GlInfo info_;
  std::recursive_mutex mutex_;
  int depth_ = 0;
  std::map<std::string, std::unique_ptr<Program>> programs_;
};

/// Throws RenderError naming the operation if GL reports an error.
void check_gl(const char* operation);

}  // namespace ambfplus::render
