#include "ambfplus/render/openxr.h"

#include <dlfcn.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <Eigen/Geometry>
#include <cstring>
#include <string>
#include <utility>

#include "ambfplus/errors.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"
#include "render/scene_renderer.h"

#if AMBFPLUS_WITH_OPENXR
#define XR_USE_PLATFORM_EGL
#define XR_USE_GRAPHICS_API_OPENGL
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>
#endif

namespace ambfplus {

#if AMBFPLUS_WITH_OPENXR

bool openxr_built() { return true; }

namespace {

constexpr std::int64_t kSrgb8Alpha8 = 0x8C43;        // GL_SRGB8_ALPHA8
constexpr std::int64_t kRgba8 = 0x8058;              // GL_RGBA8
constexpr XrDuration kImageTimeout = 1'000'000'000;  // 1 s: a runtime that long late is stuck

const char* state_name(XrSessionState state) {
  switch (state) {
    case XR_SESSION_STATE_IDLE:
      return "idle";
    case XR_SESSION_STATE_READY:
      return "ready";
    case XR_SESSION_STATE_SYNCHRONIZED:
      return "synchronized";
    case XR_SESSION_STATE_VISIBLE:
      return "visible";
    case XR_SESSION_STATE_FOCUSED:
      return "focused";
    case XR_SESSION_STATE_STOPPING:
      return "stopping";
    case XR_SESSION_STATE_LOSS_PENDING:
      return "loss_pending";
    case XR_SESSION_STATE_EXITING:
      return "exiting";
    default:
      return "unknown";
  }
}

// OpenXR's poses are in OpenGL's frame (x right, y up, z backwards); cameras are OpenCV's.
Eigen::Matrix4d opencv_pose(const XrPosef& pose) {
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                             pose.orientation.z);
  Eigen::Matrix4d gl = Eigen::Matrix4d::Identity();
  gl.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  gl.topRightCorner<3, 1>() << pose.position.x, pose.position.y, pose.position.z;
  const Eigen::Matrix4d flip = Eigen::Vector4d(1, -1, -1, 1).asDiagonal();
  return flip * gl * flip;
}

}  // namespace

struct OpenXrSession::State {
  void* loader = nullptr;
  PFN_xrGetInstanceProcAddr get_proc = nullptr;
  XrInstance instance = XR_NULL_HANDLE;
  XrSystemId system_id = XR_NULL_SYSTEM_ID;
  XrSession session = XR_NULL_HANDLE;
  XrSpace space = XR_NULL_HANDLE;
  XrSessionState state = XR_SESSION_STATE_UNKNOWN;
  XrEnvironmentBlendMode blend = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  std::string runtime, system;
  bool running = false, ended = false, in_frame = false;
  long frames = 0;
  XrTime display_time = 0;
  struct Eye {
    XrSwapchain swapchain = XR_NULL_HANDLE;
    std::vector<GLuint> images;
    int width = 0, height = 0;
  };
  std::vector<Eye> eyes;
  std::vector<XrView> views;  // located for the frame begun, empty when nothing is drawn
  GLuint framebuffer = 0;
  // The calls every frame makes, looked up once.
  PFN_xrPollEvent poll_event = nullptr;
  PFN_xrWaitFrame wait_frame = nullptr;
  PFN_xrBeginFrame begin_frame = nullptr;
  PFN_xrLocateViews locate_views = nullptr;
  PFN_xrAcquireSwapchainImage acquire_image = nullptr;
  PFN_xrWaitSwapchainImage wait_image = nullptr;
  PFN_xrReleaseSwapchainImage release_image = nullptr;
  PFN_xrEndFrame end_frame = nullptr;

  // An OpenXR function by name; throws if the runtime lacks it.
  template <typename F>
  F function(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    const XrResult r = get_proc(instance, name, &f);
    if (XR_FAILED(r) || f == nullptr) {
      throw RenderError(std::string("OpenXR: the loader has no ") + name + " (" + result_name(r) +
                        ")");
    }
    return reinterpret_cast<F>(f);
  }

  std::string result_name(XrResult r) const {
    if (instance != XR_NULL_HANDLE && get_proc != nullptr) {
      PFN_xrVoidFunction f = nullptr;
      if (XR_SUCCEEDED(get_proc(instance, "xrResultToString", &f)) && f != nullptr) {
        char text[XR_MAX_RESULT_STRING_SIZE] = {};
        if (XR_SUCCEEDED(reinterpret_cast<PFN_xrResultToString>(f)(instance, r, text))) {
          return text;
        }
      }
    }
    switch (r) {
      case XR_ERROR_RUNTIME_UNAVAILABLE:
        return "XR_ERROR_RUNTIME_UNAVAILABLE";
      case XR_ERROR_RUNTIME_FAILURE:
        return "XR_ERROR_RUNTIME_FAILURE";
      case XR_ERROR_EXTENSION_NOT_PRESENT:
        return "XR_ERROR_EXTENSION_NOT_PRESENT";
      case XR_ERROR_API_VERSION_UNSUPPORTED:
        return "XR_ERROR_API_VERSION_UNSUPPORTED";
      default:
        return "XrResult " + std::to_string(static_cast<int>(r));
    }
  }

  // Throws RenderError naming the call and the runtime's result when r is a failure.
  void check(XrResult r, const char* call) const {
    if (XR_SUCCEEDED(r)) return;
    std::string who = runtime.empty() ? "OpenXR" : "OpenXR (" + runtime + ")";
    throw RenderError(who + ": " + call + " failed: " + result_name(r));
  }

  // Opens the OpenXR loader and its entry point.
  void open_loader() {
    for (const char* name : {"libopenxr_loader.so.1", "libopenxr_loader.so"}) {
      loader = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (loader != nullptr) break;
    }
    if (loader == nullptr) {
      throw RenderError(
          "OpenXR: no loader (libopenxr_loader.so.1 cannot be opened); on Debian: apt-get install "
          "libopenxr-loader1, and a runtime such as Monado");
    }
    get_proc = reinterpret_cast<PFN_xrGetInstanceProcAddr>(dlsym(loader, "xrGetInstanceProcAddr"));
    if (get_proc == nullptr) throw RenderError("OpenXR: the loader has no xrGetInstanceProcAddr");
  }

  // Makes the instance with the extensions that hand the runtime an EGL context (the engine's is
  // EGL, with or without a window); throws when the runtime lacks them.
  void create_instance(const std::string& application) {
    static const char* const wanted[] = {XR_KHR_OPENGL_ENABLE_EXTENSION_NAME,
                                         XR_MNDX_EGL_ENABLE_EXTENSION_NAME};
    const auto extensions = enumerate<XrExtensionProperties>(
        "xrEnumerateInstanceExtensionProperties",
        [&](auto... a) {
          return function<PFN_xrEnumerateInstanceExtensionProperties>(
              "xrEnumerateInstanceExtensionProperties")(nullptr, a...);
        },
        XrExtensionProperties{XR_TYPE_EXTENSION_PROPERTIES});
    for (const char* name : wanted) {
      bool found = false;
      for (const XrExtensionProperties& e : extensions)
        found |= std::strcmp(e.extensionName, name) == 0;
      if (!found) {
        throw RenderError(std::string("OpenXR: the runtime does not offer ") + name +
                          " (ambfplus gives runtimes its EGL context; Monado does)");
      }
    }
    XrInstanceCreateInfo create{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strncpy(create.applicationInfo.applicationName, application.c_str(),
                 XR_MAX_APPLICATION_NAME_SIZE - 1);
    std::strncpy(create.applicationInfo.engineName, "ambfplus", XR_MAX_ENGINE_NAME_SIZE - 1);
    create.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    create.enabledExtensionCount = 2;
    create.enabledExtensionNames = wanted;
    check(function<PFN_xrCreateInstance>("xrCreateInstance")(&create, &instance),
          "xrCreateInstance");
  }

  // An OpenXR two-call enumeration: `call(capacity, &count, items)` asked for the count, then
  // for the items (each initialised to `blank`).
  template <typename T, typename Call>
  std::vector<T> enumerate(const char* what, Call call, T blank = T{}) const {
    uint32_t count = 0;
    check(call(0u, &count, static_cast<T*>(nullptr)), what);
    std::vector<T> items(count, blank);
    check(call(count, &count, items.data()), what);
    items.resize(count);
    return items;
  }

  // Names the runtime and finds its head-mounted display.
  void find_system() {
    XrInstanceProperties properties{XR_TYPE_INSTANCE_PROPERTIES};
    check(function<PFN_xrGetInstanceProperties>("xrGetInstanceProperties")(instance, &properties),
          "xrGetInstanceProperties");
    runtime = std::string(properties.runtimeName) + " " +
              std::to_string(XR_VERSION_MAJOR(properties.runtimeVersion)) + "." +
              std::to_string(XR_VERSION_MINOR(properties.runtimeVersion)) + "." +
              std::to_string(XR_VERSION_PATCH(properties.runtimeVersion));
    XrSystemGetInfo get{XR_TYPE_SYSTEM_GET_INFO};
    get.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    check(function<PFN_xrGetSystem>("xrGetSystem")(instance, &get, &system_id),
          "xrGetSystem (a head-mounted display)");
    XrSystemProperties system_properties{XR_TYPE_SYSTEM_PROPERTIES};
    check(function<PFN_xrGetSystemProperties>("xrGetSystemProperties")(instance, system_id,
                                                                       &system_properties),
          "xrGetSystemProperties");
    system = system_properties.systemName;
  }

  // The display's two views (their recommended image sizes), and its first blend mode.
  std::vector<XrViewConfigurationView> stereo_views() {
    const XrViewConfigurationType stereo = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    auto views_of =
        function<PFN_xrEnumerateViewConfigurationViews>("xrEnumerateViewConfigurationViews");
    auto configs = enumerate<XrViewConfigurationView>(
        "xrEnumerateViewConfigurationViews (stereo)",
        [&](auto... a) { return views_of(instance, system_id, stereo, a...); },
        XrViewConfigurationView{XR_TYPE_VIEW_CONFIGURATION_VIEW});
    if (configs.size() != 2) {
      throw RenderError("OpenXR (" + runtime + "): the stereo view configuration has " +
                        std::to_string(configs.size()) + " views, expected 2");
    }
    auto blends_of =
        function<PFN_xrEnumerateEnvironmentBlendModes>("xrEnumerateEnvironmentBlendModes");
    const auto modes = enumerate<XrEnvironmentBlendMode>(
        "xrEnumerateEnvironmentBlendModes",
        [&](auto... a) { return blends_of(instance, system_id, stereo, a...); });
    if (!modes.empty()) blend = modes.front();
    return configs;
  }

  // A session on the engine's EGL context (current in the caller's scope), after the runtime's
  // OpenGL requirements were asked for and met, and its local reference space.
  void create_session() {
    XrGraphicsRequirementsOpenGLKHR requirements{XR_TYPE_GRAPHICS_REQUIREMENTS_OPENGL_KHR};
    check(function<PFN_xrGetOpenGLGraphicsRequirementsKHR>("xrGetOpenGLGraphicsRequirementsKHR")(
              instance, system_id, &requirements),
          "xrGetOpenGLGraphicsRequirementsKHR");
    render::Context& context = render::Context::get();
    const int gl = epoxy_gl_version();  // e.g. 45
    if (XR_MAKE_VERSION(gl / 10, gl % 10, 0) < requirements.minApiVersionSupported) {
      throw RenderError("OpenXR (" + runtime + "): the runtime needs OpenGL " +
                        std::to_string(XR_VERSION_MAJOR(requirements.minApiVersionSupported)) +
                        "." +
                        std::to_string(XR_VERSION_MINOR(requirements.minApiVersionSupported)) +
                        ", the engine's context is " + context.info().version);
    }
    XrGraphicsBindingEGLMNDX binding{XR_TYPE_GRAPHICS_BINDING_EGL_MNDX};
    binding.getProcAddress = eglGetProcAddress;
    binding.display = context.display();
    binding.config = context.config();
    binding.context = context.context();
    XrSessionCreateInfo create{XR_TYPE_SESSION_CREATE_INFO};
    create.next = &binding;
    create.systemId = system_id;
    check(function<PFN_xrCreateSession>("xrCreateSession")(instance, &create, &session),
          "xrCreateSession");

    XrReferenceSpaceCreateInfo local{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    local.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    local.poseInReferenceSpace.orientation.w = 1;
    check(function<PFN_xrCreateReferenceSpace>("xrCreateReferenceSpace")(session, &local, &space),
          "xrCreateReferenceSpace (local)");
  }

  // The swapchain format: the engine's colours are sRGB-encoded bytes, so an sRGB image says
  // so; plain RGBA8 else.
  std::int64_t swapchain_format() {
    auto formats_of = function<PFN_xrEnumerateSwapchainFormats>("xrEnumerateSwapchainFormats");
    const auto formats = enumerate<std::int64_t>(
        "xrEnumerateSwapchainFormats", [&](auto... a) { return formats_of(session, a...); });
    for (std::int64_t wanted : {kSrgb8Alpha8, kRgba8}) {
      for (std::int64_t f : formats) {
        if (f == wanted) return f;
      }
    }
    throw RenderError("OpenXR (" + runtime +
                      "): the runtime offers neither GL_SRGB8_ALPHA8 nor GL_RGBA8 swapchains");
  }

  // One swapchain per view at its recommended size, its images, and the framebuffer that draws
  // into them.
  void create_swapchains(const std::vector<XrViewConfigurationView>& configs, std::int64_t format) {
    auto images_of = function<PFN_xrEnumerateSwapchainImages>("xrEnumerateSwapchainImages");
    for (const XrViewConfigurationView& config : configs) {
      Eye eye;
      eye.width = static_cast<int>(config.recommendedImageRectWidth);
      eye.height = static_cast<int>(config.recommendedImageRectHeight);
      XrSwapchainCreateInfo info{XR_TYPE_SWAPCHAIN_CREATE_INFO};
      info.usageFlags =
          XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
      info.format = format;
      info.sampleCount = 1;
      info.width = config.recommendedImageRectWidth;
      info.height = config.recommendedImageRectHeight;
      info.faceCount = 1;
      info.arraySize = 1;
      info.mipCount = 1;
      check(function<PFN_xrCreateSwapchain>("xrCreateSwapchain")(session, &info, &eye.swapchain),
            "xrCreateSwapchain");
      eyes.push_back(eye);  // destroyed with the session from here on
      const auto images = enumerate<XrSwapchainImageOpenGLKHR>(
          "xrEnumerateSwapchainImages",
          [&](uint32_t capacity, uint32_t* count, XrSwapchainImageOpenGLKHR* items) {
            return images_of(eyes.back().swapchain, capacity, count,
                             reinterpret_cast<XrSwapchainImageBaseHeader*>(items));
          },
          XrSwapchainImageOpenGLKHR{XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR});
      for (const XrSwapchainImageOpenGLKHR& image : images)
        eyes.back().images.push_back(image.image);
    }
    glGenFramebuffers(1, &framebuffer);
    render::check_gl("making the OpenXR eyes' framebuffer");
  }

  // The calls every frame makes.
  void look_up_frame_functions() {
    poll_event = function<PFN_xrPollEvent>("xrPollEvent");
    wait_frame = function<PFN_xrWaitFrame>("xrWaitFrame");
    begin_frame = function<PFN_xrBeginFrame>("xrBeginFrame");
    locate_views = function<PFN_xrLocateViews>("xrLocateViews");
    acquire_image = function<PFN_xrAcquireSwapchainImage>("xrAcquireSwapchainImage");
    wait_image = function<PFN_xrWaitSwapchainImage>("xrWaitSwapchainImage");
    release_image = function<PFN_xrReleaseSwapchainImage>("xrReleaseSwapchainImage");
    end_frame = function<PFN_xrEndFrame>("xrEndFrame");
  }

  void destroy() {
    if (instance == XR_NULL_HANDLE) return;
    {
      render::Context::Scope scope;
      for (Eye& eye : eyes) {
        if (eye.swapchain != XR_NULL_HANDLE) {
          function<PFN_xrDestroySwapchain>("xrDestroySwapchain")(eye.swapchain);
        }
      }
      if (framebuffer != 0) glDeleteFramebuffers(1, &framebuffer);
      if (space != XR_NULL_HANDLE) function<PFN_xrDestroySpace>("xrDestroySpace")(space);
      if (session != XR_NULL_HANDLE) function<PFN_xrDestroySession>("xrDestroySession")(session);
    }
    function<PFN_xrDestroyInstance>("xrDestroyInstance")(instance);
    instance = XR_NULL_HANDLE;
  }
};

OpenXrSession::OpenXrSession(const std::string& application) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.open_loader();
  s.create_instance(application);
  try {
    s.find_system();
    const std::vector<XrViewConfigurationView> views = s.stereo_views();
    render::Context::Scope scope;
    s.create_session();
    s.create_swapchains(views, s.swapchain_format());
    s.look_up_frame_functions();
  } catch (...) {
    s.destroy();
    throw;
  }
}

OpenXrSession::~OpenXrSession() {
  try {
    state_->destroy();
  } catch (const Error&) {
    // The runtime or the context is gone already; so is what they held.
  }
}

const std::string& OpenXrSession::runtime() const { return state_->runtime; }
const std::string& OpenXrSession::system() const { return state_->system; }

std::vector<std::array<int, 2>> OpenXrSession::eye_sizes() const {
  std::vector<std::array<int, 2>> out;
  for (const State::Eye& eye : state_->eyes) out.push_back({eye.width, eye.height});
  return out;
}

std::string OpenXrSession::state() const { return state_name(state_->state); }
bool OpenXrSession::running() const { return state_->running; }
bool OpenXrSession::ended() const { return state_->ended; }
long OpenXrSession::frames() const { return state_->frames; }

void OpenXrSession::poll_events() {
  State& s = *state_;
  for (;;) {
    XrEventDataBuffer event{XR_TYPE_EVENT_DATA_BUFFER};
    const XrResult r = s.poll_event(s.instance, &event);
    if (r == XR_EVENT_UNAVAILABLE) return;
    s.check(r, "xrPollEvent");
    if (event.type == XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING) {
      s.ended = true;
      s.running = false;
      continue;
    }
    if (event.type != XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) continue;
    const auto& changed = reinterpret_cast<const XrEventDataSessionStateChanged&>(event);
    s.state = changed.state;
    if (changed.state == XR_SESSION_STATE_READY) {
      XrSessionBeginInfo begin{XR_TYPE_SESSION_BEGIN_INFO};
      begin.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
      render::Context::Scope scope;
      s.check(s.function<PFN_xrBeginSession>("xrBeginSession")(s.session, &begin),
              "xrBeginSession");
      s.running = true;
    } else if (changed.state == XR_SESSION_STATE_STOPPING) {
      render::Context::Scope scope;
      s.check(s.function<PFN_xrEndSession>("xrEndSession")(s.session), "xrEndSession");
      s.running = false;
    } else if (changed.state == XR_SESSION_STATE_EXITING ||
               changed.state == XR_SESSION_STATE_LOSS_PENDING) {
      s.running = false;
      s.ended = true;
    }
  }
}

std::vector<XrEye> OpenXrSession::wait_frame() {
  State& s = *state_;
  if (!s.running) {
    throw RenderError("OpenXR (" + s.runtime + "): wait_frame while the session is " +
                      state_name(s.state) + " (poll_events() begins it when the runtime is ready)");
  }
  if (s.in_frame) throw RenderError("OpenXR: wait_frame twice without end_frame");
  XrFrameWaitInfo wait{XR_TYPE_FRAME_WAIT_INFO};
  XrFrameState frame{XR_TYPE_FRAME_STATE};
  // Waiting paces the loop to the display; the context stays free for captures meanwhile.
  s.check(s.wait_frame(s.session, &wait, &frame), "xrWaitFrame");
  s.display_time = frame.predictedDisplayTime;
  s.views.clear();
  {
    render::Context::Scope scope;
    XrFrameBeginInfo begin{XR_TYPE_FRAME_BEGIN_INFO};
    s.check(s.begin_frame(s.session, &begin), "xrBeginFrame");
  }
  s.in_frame = true;
  std::vector<XrEye> eyes;
  if (!frame.shouldRender) return eyes;
  XrViewLocateInfo locate{XR_TYPE_VIEW_LOCATE_INFO};
  locate.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  locate.displayTime = frame.predictedDisplayTime;
  locate.space = s.space;
  XrViewState view_state{XR_TYPE_VIEW_STATE};
  std::vector<XrView> views(s.eyes.size(), {XR_TYPE_VIEW});
  uint32_t count = 0;
  s.check(s.locate_views(s.session, &locate, &view_state, static_cast<uint32_t>(views.size()),
                         &count, views.data()),
          "xrLocateViews");
  // Without a tracked orientation there is nothing to draw this frame (the frame still ends).
  if (!(view_state.viewStateFlags & XR_VIEW_STATE_ORIENTATION_VALID_BIT) || count != views.size()) {
    return eyes;
  }
  s.views = views;
  for (std::size_t i = 0; i < views.size(); ++i) {
    XrEye eye;
    eye.pose = opencv_pose(views[i].pose);
    eye.fov = {views[i].fov.angleLeft, views[i].fov.angleRight, views[i].fov.angleUp,
               views[i].fov.angleDown};
    eye.width = s.eyes[i].width;
    eye.height = s.eyes[i].height;
    eyes.push_back(eye);
  }
  return eyes;
}

std::vector<Frame> OpenXrSession::end_frame(const std::vector<const Camera*>& cameras) {
  State& s = *state_;
  if (!s.in_frame) throw RenderError("OpenXR: end_frame without wait_frame");
  s.in_frame = false;
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.displayTime = s.display_time;
  end.environmentBlendMode = s.blend;
  std::vector<Frame> frames;
  std::vector<XrCompositionLayerProjectionView> projected;
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&layer)};
  auto finish = [&] {
    render::Context::Scope scope;
    s.check(s.end_frame(s.session, &end), "xrEndFrame");
  };
  if (s.views.empty()) {
    finish();
    return frames;
  }
  if (cameras.size() != s.views.size()) {
    finish();
    throw ArgumentError("OpenXR: end_frame needs a camera per eye (" +
                        std::to_string(s.views.size()) + "), got " +
                        std::to_string(cameras.size()));
  }
  frames.resize(cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const render::RenderTarget& target =
        static_cast<render::SceneRenderer&>(render::renderer_of(cameras[i]->world()))
            .render_to_target(*cameras[i], kPassRgb, frames[i]);
    State::Eye& eye = s.eyes[i];
    render::Context::Scope scope;
    uint32_t index = 0;
    XrSwapchainImageAcquireInfo acquire_info{XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO};
    s.check(s.acquire_image(eye.swapchain, &acquire_info, &index), "xrAcquireSwapchainImage");
    XrSwapchainImageWaitInfo wait_info{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wait_info.timeout = kImageTimeout;
    const XrResult waited = s.wait_image(eye.swapchain, &wait_info);
    if (waited == XR_TIMEOUT_EXPIRED) {
      throw RenderError("OpenXR (" + s.runtime + "): a swapchain image was not free within 1 s");
    }
    s.check(waited, "xrWaitSwapchainImage");
    // The camera's row 0 (its target's first row) is the image's top; an OpenGL swapchain
    // image's first row is its bottom. sRGB encoding stays off: the bytes go over as they are.
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, s.framebuffer);
    glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                           eye.images.at(index), 0);
    glDrawBuffer(GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glBlitFramebuffer(0, 0, target.width, target.height, 0, eye.height, eye.width, 0,
                      GL_COLOR_BUFFER_BIT, GL_LINEAR);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    render::check_gl("copying an eye into its OpenXR swapchain image");
    XrSwapchainImageReleaseInfo release_info{XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO};
    s.check(s.release_image(eye.swapchain, &release_info), "xrReleaseSwapchainImage");

    XrCompositionLayerProjectionView view{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
    view.pose = s.views[i].pose;
    view.fov = s.views[i].fov;
    view.subImage.swapchain = eye.swapchain;
    view.subImage.imageRect.extent = {eye.width, eye.height};
    projected.push_back(view);
  }
  layer.space = s.space;
  layer.viewCount = static_cast<uint32_t>(projected.size());
  layer.views = projected.data();
  end.layerCount = 1;
  end.layers = layers;
  finish();
  ++s.frames;
  return frames;
}

void OpenXrSession::request_exit() {
  State& s = *state_;
  if (!s.running) return;
  s.check(s.function<PFN_xrRequestExitSession>("xrRequestExitSession")(s.session),
          "xrRequestExitSession");
}

#else  // built without OpenXR's headers

bool openxr_built() { return false; }

struct OpenXrSession::State {};

OpenXrSession::OpenXrSession(const std::string&) {
  throw RenderError(
      "OpenXR: ambfplus was built without OpenXR's headers (on Debian: apt-get install "
      "libopenxr-dev, then reinstall ambfplus)");
}
OpenXrSession::~OpenXrSession() = default;
const std::string& OpenXrSession::runtime() const { throw RenderError("OpenXR: not built"); }
const std::string& OpenXrSession::system() const { throw RenderError("OpenXR: not built"); }
std::vector<std::array<int, 2>> OpenXrSession::eye_sizes() const { return {}; }
std::string OpenXrSession::state() const { return "unknown"; }
bool OpenXrSession::running() const { return false; }
bool OpenXrSession::ended() const { return true; }
long OpenXrSession::frames() const { return 0; }
void OpenXrSession::poll_events() {}
std::vector<XrEye> OpenXrSession::wait_frame() { throw RenderError("OpenXR: not built"); }
std::vector<Frame> OpenXrSession::end_frame(const std::vector<const Camera*>&) {
  throw RenderError("OpenXR: not built");
}
void OpenXrSession::request_exit() {}

#endif

}  // namespace ambfplus
