#include "render/egl_context.h"

#include <unistd.h>

#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"

namespace ambfplus::render {
namespace {

std::string egl_error_name(EGLint code) {
  switch (code) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default: {
      std::ostringstream s;
      s << "EGL error 0x" << std::hex << code;
      return s.str();
    }
  }
}

bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::string all = std::string(" ") + list + " ";
  return all.find(std::string(" ") + name + " ") != std::string::npos;
}

// An initialised display with a current OpenGL 4.5 context, or the reason there is none.
struct Candidate {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLConfig config = nullptr;
  std::string profile;
  std::string failure;
};

// With `windows`, the config must also draw into window surfaces (a window system's display).
Candidate open_display(EGLDisplay display, bool windows = false) {
  Candidate c;
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY) {
    c.failure = "no display (" + egl_error_name(eglGetError()) + ")";
    return c;
  }
  if (!eglInitialize(display, &major, &minor)) {
    c.failure = "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
    return c;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    eglTerminate(display);
    c.failure = "no EGL_KHR_surfaceless_context";
    return c;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    eglTerminate(display);
    c.failure = "no desktop OpenGL API (" + egl_error_name(eglGetError()) + ")";
    return c;
  }
  EGLConfig config = nullptr;
  const EGLint surfaces = windows ? EGL_WINDOW_BIT | EGL_PBUFFER_BIT : EGL_PBUFFER_BIT;
  const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT,
                                      EGL_SURFACE_TYPE,
                                      surfaces,
                                      EGL_RED_SIZE,
                                      8,
                                      EGL_GREEN_SIZE,
                                      8,
                                      EGL_BLUE_SIZE,
                                      8,
                                      EGL_NONE};
  EGLint count = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &count) || count == 0) {
    if (windows || !has_extension(extensions, "EGL_KHR_no_config_context")) {
      eglTerminate(display);
      c.failure = "no OpenGL-renderable EGL config";
      return c;
    }
    config = EGL_NO_CONFIG_KHR;
  }
  // A compatibility profile keeps AMBF's legacy GLSL shaders usable; core is the fallback.
  const struct {
    EGLint mask;
    const char* name;
  } profiles[] = {{EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT, "compatibility"},
                  {EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, "core"}};
  for (const auto& p : profiles) {
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 4,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 p.mask,
                                 EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    if (context == EGL_NO_CONTEXT) continue;
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      c.display = display;
      c.context = context;
      c.config = config;
      c.profile = p.name;
      return c;
    }
    eglDestroyContext(display, context);
  }
  eglTerminate(display);
  c.failure = "no OpenGL 4.5 context (" + egl_error_name(eglGetError()) + ")";
  return c;
}

// Parses a non-negative integer environment variable; -1 when unset.
int env_index(const char* name) {
  const char* value = std::getenv(name);
  if (value == nullptr || *value == '\0') return -1;
  char* end = nullptr;
  const long v = std::strtol(value, &end, 10);
  if (*end != '\0' || v < 0 || v > 1024) {
    throw RenderError(std::string(name) + "='" + value + "' is not a device index (0, 1, ...)");
  }
  return static_cast<int>(v);
}

std::string gl_string(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "";
}

// The one context of this process; destroyed at exit after every world released its resources.
std::unique_ptr<Context>& instance_slot() {
  static std::unique_ptr<Context> slot;
  return slot;
}

std::mutex& creation_mutex() {
  static std::mutex m;
  return m;
}

// The window system's display a windowed process renders through (GLFW's X11 Display*).
void*& x11_display() {
  static void* display = nullptr;
  return display;
}

}  // namespace

void Context::use_x11_display(void* display) {
  std::lock_guard<std::mutex> lock(creation_mutex());
  auto& slot = instance_slot();
  if (slot && slot->pid_ == getpid() && x11_display() != display) {
    throw RenderError(
        "a window needs the engine's OpenGL context on its X11 display, but this process "
        "rendered before the window was opened: open windows before the first capture");
  }
  x11_display() = display;
}

Context& Context::get() {
  std::lock_guard<std::mutex> lock(creation_mutex());
  auto& slot = instance_slot();
  if (!slot) {
    slot.reset(new Context());
  } else if (slot->pid_ != getpid()) {
    throw RenderError(
        "the EGL context was created in process " + std::to_string(slot->pid_) +
        " before this process (" + std::to_string(getpid()) +
        ") was forked from it; a GL context cannot cross a fork: render only in the process "
        "that first renders (create worlds and cameras inside worker processes)");
  }
  return *slot;
}

Context::Context() : pid_(getpid()) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const bool can_enumerate = has_extension(client, "EGL_EXT_device_enumeration") &&
                             has_extension(client, "EGL_EXT_platform_device");
  std::vector<EGLDeviceEXT> devices;
  if (can_enumerate) {
    EGLint count = 0;
    eglQueryDevicesEXT(0, nullptr, &count);
    devices.resize(count);
    if (count > 0) eglQueryDevicesEXT(count, devices.data(), &count);
    devices.resize(count);
  }
  auto device_display = [&](int i) {
    return eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
  };
  auto describe = [&](int i) {
    const char* ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
    return "EGL device " + std::to_string(i) + " [" + (ext ? ext : "") + "]";
  };

  Candidate chosen;
  std::string how;
  const int egl_index = env_index("AMBFPLUS_EGL_DEVICE");
  const int cuda_index = env_index("AMBFPLUS_CUDA_DEVICE");
  if (x11_display() != nullptr) {
    // Windows present this context: its display is the window system's.
    chosen =
        open_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_X11_KHR, x11_display(), nullptr), true);
    if (!chosen.failure.empty()) {
      throw RenderError("the X11 display of the window: " + chosen.failure +
                        " (is DISPLAY an X server with GLX/EGL support, e.g. Xvfb?)");
    }
    how = "the X11 display of a window";
  } else if (egl_index >= 0) {
    if (egl_index >= static_cast<int>(devices.size())) {
      throw RenderError("AMBFPLUS_EGL_DEVICE=" + std::to_string(egl_index) +
                        " but this machine has " + std::to_string(devices.size()) +
                        " EGL device(s)");
    }
    chosen = open_display(device_display(egl_index));
    if (!chosen.failure.empty()) {
      throw RenderError("AMBFPLUS_EGL_DEVICE=" + std::to_string(egl_index) + ": " +
                        describe(egl_index) + ": " + chosen.failure);
    }
    info_.device_index = egl_index;
    how = describe(egl_index) + ", chosen by AMBFPLUS_EGL_DEVICE";
  } else if (cuda_index >= 0) {
    int match = -1;
    for (int i = 0; i < static_cast<int>(devices.size()) && match < 0; ++i) {
      const char* ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
      EGLAttrib ordinal = -1;
      if (has_extension(ext, "EGL_NV_device_cuda") &&
          eglQueryDeviceAttribEXT(devices[i], EGL_CUDA_DEVICE_NV, &ordinal) &&
          ordinal == cuda_index) {
        match = i;
      }
    }
    if (match < 0) {
      throw RenderError("AMBFPLUS_CUDA_DEVICE=" + std::to_string(cuda_index) +
                        " but no EGL device reports that CUDA ordinal (needs the NVIDIA driver's "
                        "EGL_NV_device_cuda; " +
                        std::to_string(devices.size()) + " EGL device(s) found)");
    }
    chosen = open_display(device_display(match));
    if (!chosen.failure.empty()) {
      throw RenderError("AMBFPLUS_CUDA_DEVICE=" + std::to_string(cuda_index) + ": " +
                        describe(match) + ": " + chosen.failure);
    }
    info_.device_index = match;
    how = describe(match) + ", CUDA device " + std::to_string(cuda_index);
  } else {
    std::string tried;
    for (int i = 0; i < static_cast<int>(devices.size()); ++i) {
      chosen = open_display(device_display(i));
      if (chosen.failure.empty()) {
        info_.device_index = i;
        how = describe(i) + ", the first that initialised";
        break;
      }
      tried += "; " + describe(i) + ": " + chosen.failure;
    }
    if (chosen.display == EGL_NO_DISPLAY) {
      if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
        chosen = open_display(
            eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
        how = "Mesa surfaceless platform";
        if (!chosen.failure.empty()) tried += "; Mesa surfaceless: " + chosen.failure;
      } else {
        tried += "; no Mesa surfaceless platform";
      }
    }
    if (chosen.display == EGL_NO_DISPLAY) {
      throw RenderError(
          "no OpenGL 4.5 context through EGL: " + std::to_string(devices.size()) +
          " EGL device(s)" + tried +
          ". Install an EGL driver: on Debian, libegl1 libegl-mesa0 libgl1-mesa-dri (software "
          "rendering) or the GPU vendor's driver");
    }
  }
  display_ = chosen.display;
  context_ = chosen.context;
  config_ = chosen.config;
  info_.profile = chosen.profile;
  info_.platform = x11_display() != nullptr  ? "x11"
                   : info_.device_index >= 0 ? "device"
                                             : "surfaceless";
  info_.device = how;
  info_.vendor = gl_string(GL_VENDOR);
  info_.renderer = gl_string(GL_RENDERER);
  info_.version = gl_string(GL_VERSION);
  info_.glsl_version = gl_string(GL_SHADING_LANGUAGE_VERSION);
  const char* egl_vendor = eglQueryString(display_, EGL_VENDOR);
  const char* egl_version = eglQueryString(display_, EGL_VERSION);
  info_.egl_vendor = egl_vendor ? egl_vendor : "";
  info_.egl_version = egl_version ? egl_version : "";
  release();
  log(LogLevel::kInfo, "OpenGL " + info_.version + " (" + info_.profile + ") on " + info_.renderer +
                           " by " + info_.vendor + "; " + how);
}

Context::~Context() {
  // Runs at exit. A driver may have torn itself down before: NVIDIA's EGL library registers an
  // exit handler of its own, after this context's, so it runs first. No GL call may then be made
  // (libepoxy aborts the process when no context is current): the programs go with the process.
  // A forked child must not tear down its parent's driver state either.
  if (pid_ == getpid() && eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    programs_.clear();
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
    return;
  }
  for (auto& p : programs_) p.second.release();
}

bool Context::exists() {
  std::lock_guard<std::mutex> lock(creation_mutex());
  return instance_slot() != nullptr && instance_slot()->pid_ == getpid();
}

Program& Context::program(const std::string& vertex_file, const std::string& fragment_file,
                          const std::string& defines) {
  const std::string key = vertex_file + "|" + fragment_file + "|" + defines;
  auto it = programs_.find(key);
  if (it == programs_.end()) {
    const std::string dir = shader_dir();
    it = programs_
             .emplace(key, std::make_unique<Program>(dir + "/" + vertex_file,
                                                     dir + "/" + fragment_file, defines))
             .first;
  }
  return *it->second;
}

Program& Context::program(const std::string& key,
                          const std::function<std::unique_ptr<Program>()>& make) {
  auto it = programs_.find(key);
  if (it == programs_.end()) it = programs_.emplace(key, make()).first;
  return *it->second;
}

void Context::make_current(EGLSurface surface) {
  if (!eglMakeCurrent(display_, surface, surface, context_)) {
    throw RenderError("eglMakeCurrent with a window surface failed: " +
                      egl_error_name(eglGetError()));
  }
}

std::string Context::error_name() { return egl_error_name(eglGetError()); }

void Context::make_current() {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw RenderError("eglMakeCurrent failed: " + egl_error_name(eglGetError()));
  }
}

void Context::release() {
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

Context::Scope::Scope() : context_(Context::get()) {
  context_.mutex_.lock();
  if (context_.depth_ == 0) {
    try {
      context_.make_current();
    } catch (...) {
      context_.mutex_.unlock();
      throw;
    }
  }
  ++context_.depth_;
}

// Released at the end of every outermost scope: EGL lets a context be current on one thread only,
// and the next capture may come from another thread.
Context::Scope::~Scope() {
  if (--context_.depth_ == 0) context_.release();
  context_.mutex_.unlock();
}

void check_gl(const char* operation) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  std::ostringstream s;
  s << operation << ": OpenGL error 0x" << std::hex << error;
  while (glGetError() != GL_NO_ERROR) {
  }
  throw RenderError(s.str());
}

GlInfo gl_info_impl() { return Context::get().info(); }

}  // namespace ambfplus::render

namespace ambfplus {
GlInfo gl_info() { return render::gl_info_impl(); }
}  // namespace ambfplus
