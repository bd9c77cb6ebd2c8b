// An OpenXR runtime for the tests: a head-mounted display without hardware, loaded by the Khronos
// loader (XR_RUNTIME_JSON) exactly as Monado or SteamVR would be. It takes the application's EGL
// context (XR_MNDX_egl_enable), makes its swapchain images as GL textures in it, and checks the
// calls it gets: their order, their structures, and that the application's context is current
// whenever the runtime must use it. What it is told through the environment:
//
//   AMBFPLUS_XR_HEAD       a file "qx qy qz qw [px py pz]": the head's pose in the LOCAL space,
//                          read at every xrLocateViews (absent: the head at the origin)
//   AMBFPLUS_XR_DUMP       a directory: each submitted frame's eyes as eye0.ppm / eye1.ppm (the
//                          last frame), and a line per frame in frames.jsonl
//   AMBFPLUS_XR_EXIT_AFTER the runtime ends the session itself after this many frames
//   AMBFPLUS_XR_SIZE       each eye's recommended image, "WxH" (default 320x240)
//   AMBFPLUS_XR_NO_EGL     set: the runtime does not offer XR_MNDX_egl_enable
//
// Errors it finds are printed to stderr with "test runtime:" and returned as XrResults.

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#define XR_USE_PLATFORM_EGL
#define XR_USE_GRAPHICS_API_OPENGL
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

// The loader's negotiation structures (OpenXR loader documentation, "Runtime interface
// negotiation"); Debian's 1.0.20 headers do not install them.
enum XrLoaderInterfaceStructs {
  XR_LOADER_INTERFACE_STRUCT_UNINTIALIZED = 0,
  XR_LOADER_INTERFACE_STRUCT_LOADER_INFO,
  XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST,
  XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST,
};
struct XrNegotiateLoaderInfo {
  XrLoaderInterfaceStructs structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t minInterfaceVersion;
  uint32_t maxInterfaceVersion;
  XrVersion minApiVersion;
  XrVersion maxApiVersion;
};
struct XrNegotiateRuntimeRequest {
  XrLoaderInterfaceStructs structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t runtimeInterfaceVersion;
  XrVersion runtimeApiVersion;
  PFN_xrGetInstanceProcAddr getInstanceProcAddr;
};

namespace {

constexpr double kIpd = 0.064;
// Each eye's field of view, the left eye's; the right eye's mirrors it.
constexpr float kFov[4] = {-0.62f, 0.48f, 0.45f, -0.52f};
constexpr int kImages = 3;

struct Swapchain;

struct Runtime {
  bool instance = false;
  bool requirements_asked = false;
  bool session = false;
  bool running = false;
  bool frame_waited = false, frame_begun = false;
  long frames = 0;
  std::deque<XrSessionState> events;
  XrGraphicsBindingEGLMNDX binding{};
  std::vector<Swapchain*> swapchains;
  std::array<XrView, 2> located{};
  bool exit_sent = false;
} g;

struct Swapchain {
  std::vector<GLuint> textures;
  int width = 0, height = 0;
  int acquired = -1, waited = -1, released = -1;
  int next = 0;
};

XrResult fail(XrResult result, const std::string& why) {
  std::fprintf(stderr, "test runtime: %s\n", why.c_str());
  return result;
}

std::array<int, 2> eye_size() {
  std::array<int, 2> size{320, 240};
  if (const char* text = std::getenv("AMBFPLUS_XR_SIZE")) {
    std::sscanf(text, "%dx%d", &size[0], &size[1]);
  }
  return size;
}

template <typename F>
F gl(const char* name) {
  return reinterpret_cast<F>(g.binding.getProcAddress(name));
}

// The runtime may only use the application's context while the application has it current.
bool context_current() {
  auto current = gl<EGLContext (*)()>("eglGetCurrentContext");
  return current != nullptr && current() == g.binding.context;
}

XrPosef head_pose() {
  XrPosef pose{};
  pose.orientation.w = 1;
  const char* path = std::getenv("AMBFPLUS_XR_HEAD");
  if (path == nullptr) return pose;
  std::ifstream in(path);
  float v[7] = {0, 0, 0, 1, 0, 0, 0};
  for (float& x : v) {
    if (!(in >> x)) break;
  }
  const float n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
  pose.orientation = {v[0] / n, v[1] / n, v[2] / n, v[3] / n};
  pose.position = {v[4], v[5], v[6]};
  return pose;
}

// q * v for a unit quaternion.
XrVector3f rotate(const XrQuaternionf& q, const XrVector3f& v) {
  const XrVector3f u{q.x, q.y, q.z};
  auto cross = [](XrVector3f a, XrVector3f b) {
    return XrVector3f{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const XrVector3f t = cross(u, v);
  const XrVector3f t2{2 * t.x, 2 * t.y, 2 * t.z};
  const XrVector3f c = cross(u, t2);
  return {v.x + q.w * t2.x + c.x, v.y + q.w * t2.y + c.y, v.z + q.w * t2.z + c.z};
}

XrTime now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::ostream& write_json_view(std::ostream& out, const XrPosef& p, const XrFovf& f) {
  out << "{\"pose\": [" << p.orientation.x << ", " << p.orientation.y << ", " << p.orientation.z
      << ", " << p.orientation.w << ", " << p.position.x << ", " << p.position.y << ", "
      << p.position.z << "], \"fov\": [" << f.angleLeft << ", " << f.angleRight << ", " << f.angleUp
      << ", " << f.angleDown << "]";
  return out;
}

XrResult dump(const XrCompositionLayerProjection& layer, XrTime display_time) {
  const char* dir = std::getenv("AMBFPLUS_XR_DUMP");
  if (dir == nullptr) return XR_SUCCESS;
  auto get_image = gl<void (*)(GLuint, GLint, GLenum, GLenum, GLsizei, void*)>("glGetTextureImage");
  std::ofstream log(std::string(dir) + "/frames.jsonl", std::ios::app);
  log.precision(9);
  log << "{\"frame\": " << g.frames << ", \"display_time\": " << display_time << ", \"views\": [";
  for (uint32_t i = 0; i < layer.viewCount; ++i) {
    const XrCompositionLayerProjectionView& v = layer.views[i];
    auto* chain = reinterpret_cast<Swapchain*>(v.subImage.swapchain);
    write_json_view(log << (i ? ", " : ""), v.pose, v.fov);
    const XrRect2Di& r = v.subImage.imageRect;
    log << ", \"rect\": [" << r.offset.x << ", " << r.offset.y << ", " << r.extent.width << ", "
        << r.extent.height << "], \"image\": " << chain->released << "}";
    std::vector<unsigned char> rgba(4u * chain->width * chain->height);
    get_image(chain->textures[chain->released], 0, GL_RGBA, GL_UNSIGNED_BYTE,
              static_cast<GLsizei>(rgba.size()), rgba.data());
    std::ofstream ppm(std::string(dir) + "/eye" + std::to_string(i) + ".ppm", std::ios::binary);
    ppm << "P6\n" << chain->width << " " << chain->height << "\n255\n";
    // A GL texture's first row is its bottom; a picture's is its top.
    for (int y = chain->height - 1; y >= 0; --y) {
      for (int x = 0; x < chain->width; ++x)
        ppm.write(reinterpret_cast<char*>(&rgba[4u * (y * chain->width + x)]), 3);
    }
  }
  log << "], \"located\": [";
  for (int i = 0; i < 2; ++i)
    write_json_view(log << (i ? ", " : ""), g.located[i].pose, g.located[i].fov) << "}";
  log << "]}\n";
  return XR_SUCCESS;
}

// --- the API ---------------------------------------------------------------------------------

XrResult XRAPI_CALL enumerate_extensions(const char* layer, uint32_t capacity, uint32_t* count,
                                         XrExtensionProperties* out) {
  std::vector<std::string> names{XR_KHR_OPENGL_ENABLE_EXTENSION_NAME};
  if (std::getenv("AMBFPLUS_XR_NO_EGL") == nullptr) {
    names.push_back(XR_MNDX_EGL_ENABLE_EXTENSION_NAME);
  }
  *count = static_cast<uint32_t>(names.size());
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < names.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::strncpy(out[i].extensionName, names[i].c_str(), XR_MAX_EXTENSION_NAME_SIZE - 1);
    out[i].extensionVersion = 1;
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL create_instance(const XrInstanceCreateInfo* info, XrInstance* instance) {
  if (info == nullptr || info->type != XR_TYPE_INSTANCE_CREATE_INFO) {
    return fail(XR_ERROR_VALIDATION_FAILURE, "xrCreateInstance: not an XrInstanceCreateInfo");
  }
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
    const std::string name = info->enabledExtensionNames[i];
    const bool egl = name == XR_MNDX_EGL_ENABLE_EXTENSION_NAME;
    if (name != XR_KHR_OPENGL_ENABLE_EXTENSION_NAME &&
        (!egl || std::getenv("AMBFPLUS_XR_NO_EGL") != nullptr)) {
      return fail(XR_ERROR_EXTENSION_NOT_PRESENT, "xrCreateInstance: no extension " + name);
    }
  }
  g = Runtime{};
  g.instance = true;
  *instance = reinterpret_cast<XrInstance>(&g);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL destroy_instance(XrInstance) {
  g.instance = false;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL instance_properties(XrInstance, XrInstanceProperties* p) {
  p->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
  std::strncpy(p->runtimeName, "ambfplus test runtime", XR_MAX_RUNTIME_NAME_SIZE - 1);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL result_to_string(XrInstance, XrResult result, char* out) {
  std::snprintf(out, XR_MAX_RESULT_STRING_SIZE, "XR_RESULT_%d", static_cast<int>(result));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL get_system(XrInstance, const XrSystemGetInfo* info, XrSystemId* id) {
  if (info->formFactor != XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY) {
    return XR_ERROR_FORM_FACTOR_UNSUPPORTED;
  }
  *id = 1;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL system_properties(XrInstance, XrSystemId, XrSystemProperties* p) {
  std::strncpy(p->systemName, "test headset", XR_MAX_SYSTEM_NAME_SIZE - 1);
  p->systemId = 1;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL view_configuration_views(XrInstance, XrSystemId, XrViewConfigurationType type,
                                             uint32_t capacity, uint32_t* count,
                                             XrViewConfigurationView* views) {
  if (type != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) {
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  }
  *count = 2;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < 2) return XR_ERROR_SIZE_INSUFFICIENT;
  const auto size = eye_size();
  for (int i = 0; i < 2; ++i) {
    if (views[i].type != XR_TYPE_VIEW_CONFIGURATION_VIEW) {
      return fail(XR_ERROR_VALIDATION_FAILURE, "not an XrViewConfigurationView");
    }
    views[i].recommendedImageRectWidth = static_cast<uint32_t>(size[0]);
    views[i].recommendedImageRectHeight = static_cast<uint32_t>(size[1]);
    views[i].maxImageRectWidth = 4096;
    views[i].maxImageRectHeight = 4096;
    views[i].recommendedSwapchainSampleCount = 1;
    views[i].maxSwapchainSampleCount = 1;
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL blend_modes(XrInstance, XrSystemId, XrViewConfigurationType, uint32_t capacity,
                                uint32_t* count, XrEnvironmentBlendMode* modes) {
  *count = 1;
  if (capacity >= 1) modes[0] = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL gl_requirements(XrInstance, XrSystemId, XrGraphicsRequirementsOpenGLKHR* r) {
  if (r->type != XR_TYPE_GRAPHICS_REQUIREMENTS_OPENGL_KHR) {
    return fail(XR_ERROR_VALIDATION_FAILURE, "not an XrGraphicsRequirementsOpenGLKHR");
  }
  r->minApiVersionSupported = XR_MAKE_VERSION(3, 3, 0);
  r->maxApiVersionSupported = XR_MAKE_VERSION(4, 6, 0);
  g.requirements_asked = true;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL create_session(XrInstance, const XrSessionCreateInfo* info,
                                   XrSession* session) {
  if (!g.requirements_asked) {
    return fail(XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING,
                "xrCreateSession before xrGetOpenGLGraphicsRequirementsKHR");
  }
  const auto* binding = static_cast<const XrGraphicsBindingEGLMNDX*>(info->next);
  if (binding == nullptr || binding->type != XR_TYPE_GRAPHICS_BINDING_EGL_MNDX ||
      binding->getProcAddress == nullptr || binding->context == EGL_NO_CONTEXT) {
    return fail(XR_ERROR_GRAPHICS_DEVICE_INVALID, "xrCreateSession: no EGL binding");
  }
  g.binding = *binding;
  g.session = true;
  g.events = {XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY};
  *session = reinterpret_cast<XrSession>(&g.binding);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL destroy_session(XrSession) {
  g.session = false;
  g.running = false;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL poll_event(XrInstance, XrEventDataBuffer* event) {
  if (g.events.empty()) return XR_EVENT_UNAVAILABLE;
  auto* changed = reinterpret_cast<XrEventDataSessionStateChanged*>(event);
  changed->type = XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED;
  changed->next = nullptr;
  changed->session = reinterpret_cast<XrSession>(&g.binding);
  changed->state = g.events.front();
  changed->time = now();
  g.events.pop_front();
  return XR_SUCCESS;
}

XrResult XRAPI_CALL begin_session(XrSession, const XrSessionBeginInfo* info) {
  if (g.running) return XR_ERROR_SESSION_RUNNING;
  if (info->primaryViewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) {
    return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
  }
  g.running = true;
  for (XrSessionState s :
       {XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_FOCUSED}) {
    g.events.push_back(s);
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL end_session(XrSession) {
  if (!g.running) return XR_ERROR_SESSION_NOT_RUNNING;
  g.running = false;
  g.events.push_back(XR_SESSION_STATE_IDLE);
  g.events.push_back(XR_SESSION_STATE_EXITING);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL request_exit(XrSession) {
  if (!g.running) return XR_ERROR_SESSION_NOT_RUNNING;
  for (XrSessionState s :
       {XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_STOPPING}) {
    g.events.push_back(s);
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL create_space(XrSession, const XrReferenceSpaceCreateInfo* info,
                                 XrSpace* space) {
  if (info->referenceSpaceType != XR_REFERENCE_SPACE_TYPE_LOCAL &&
      info->referenceSpaceType != XR_REFERENCE_SPACE_TYPE_VIEW) {
    return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
  }
  *space = reinterpret_cast<XrSpace>(new int(info->referenceSpaceType));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL destroy_space(XrSpace space) {
  delete reinterpret_cast<int*>(space);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL swapchain_formats(XrSession, uint32_t capacity, uint32_t* count,
                                      int64_t* formats) {
  *count = 2;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < 2) return XR_ERROR_SIZE_INSUFFICIENT;
  formats[0] = GL_SRGB8_ALPHA8;
  formats[1] = GL_RGBA8;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL create_swapchain(XrSession, const XrSwapchainCreateInfo* info,
                                     XrSwapchain* out) {
  if (!context_current()) {
    return fail(XR_ERROR_RUNTIME_FAILURE,
                "xrCreateSwapchain: the session's context is not current");
  }
  if (info->format != GL_SRGB8_ALPHA8 && info->format != GL_RGBA8) {
    return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;
  }
  auto* chain = new Swapchain;
  chain->width = static_cast<int>(info->width);
  chain->height = static_cast<int>(info->height);
  chain->textures.resize(kImages);
  gl<void (*)(GLsizei, GLuint*)>("glGenTextures")(kImages, chain->textures.data());
  for (GLuint t : chain->textures) {
    gl<void (*)(GLenum, GLuint)>("glBindTexture")(GL_TEXTURE_2D, t);
    gl<void (*)(GLenum, GLsizei, GLenum, GLsizei, GLsizei)>("glTexStorage2D")(
        GL_TEXTURE_2D, 1, static_cast<GLenum>(info->format), chain->width, chain->height);
  }
  g.swapchains.push_back(chain);
  *out = reinterpret_cast<XrSwapchain>(chain);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL destroy_swapchain(XrSwapchain swapchain) {
  auto* chain = reinterpret_cast<Swapchain*>(swapchain);
  if (!context_current()) {
    return fail(XR_ERROR_RUNTIME_FAILURE,
                "xrDestroySwapchain: the session's context is not current");
  }
  gl<void (*)(GLsizei, const GLuint*)>("glDeleteTextures")(kImages, chain->textures.data());
  delete chain;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL swapchain_images(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                     XrSwapchainImageBaseHeader* images) {
  auto* chain = reinterpret_cast<Swapchain*>(swapchain);
  *count = kImages;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < kImages) return XR_ERROR_SIZE_INSUFFICIENT;
  auto* gl_images = reinterpret_cast<XrSwapchainImageOpenGLKHR*>(images);
  for (int i = 0; i < kImages; ++i) {
    if (gl_images[i].type != XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR) {
      return fail(XR_ERROR_VALIDATION_FAILURE, "not an XrSwapchainImageOpenGLKHR");
    }
    gl_images[i].image = chain->textures[i];
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL acquire_image(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo*,
                                  uint32_t* index) {
  auto* chain = reinterpret_cast<Swapchain*>(swapchain);
  if (chain->acquired >= 0) return fail(XR_ERROR_CALL_ORDER_INVALID, "acquired twice");
  chain->acquired = chain->next;
  chain->next = (chain->next + 1) % kImages;
  *index = static_cast<uint32_t>(chain->acquired);
  return XR_SUCCESS;
}

XrResult XRAPI_CALL wait_image(XrSwapchain swapchain, const XrSwapchainImageWaitInfo*) {
  auto* chain = reinterpret_cast<Swapchain*>(swapchain);
  if (chain->acquired < 0) return fail(XR_ERROR_CALL_ORDER_INVALID, "wait without acquire");
  chain->waited = chain->acquired;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL release_image(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo*) {
  auto* chain = reinterpret_cast<Swapchain*>(swapchain);
  if (chain->waited < 0) return fail(XR_ERROR_CALL_ORDER_INVALID, "release without wait");
  chain->released = chain->waited;
  chain->acquired = chain->waited = -1;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL wait_frame(XrSession, const XrFrameWaitInfo*, XrFrameState* state) {
  if (!g.running) return XR_ERROR_SESSION_NOT_RUNNING;
  if (state->type != XR_TYPE_FRAME_STATE) {
    return fail(XR_ERROR_VALIDATION_FAILURE, "not an XrFrameState");
  }
  g.frame_waited = true;
  state->predictedDisplayTime = now() + 11'000'000;
  state->predictedDisplayPeriod = 11'111'111;
  state->shouldRender = XR_TRUE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL begin_frame(XrSession, const XrFrameBeginInfo*) {
  if (!g.frame_waited) return fail(XR_ERROR_CALL_ORDER_INVALID, "xrBeginFrame without xrWaitFrame");
  g.frame_waited = false;
  g.frame_begun = true;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL locate_views(XrSession, const XrViewLocateInfo* info, XrViewState* state,
                                 uint32_t capacity, uint32_t* count, XrView* views) {
  *count = 2;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < 2) return XR_ERROR_SIZE_INSUFFICIENT;
  const XrPosef head = head_pose();
  state->viewStateFlags = XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT |
                          XR_VIEW_STATE_ORIENTATION_TRACKED_BIT;
  for (int i = 0; i < 2; ++i) {
    if (views[i].type != XR_TYPE_VIEW) return fail(XR_ERROR_VALIDATION_FAILURE, "not an XrView");
    const float side = i == 0 ? -1.0f : 1.0f;
    const XrVector3f eye = rotate(head.orientation, {side * static_cast<float>(kIpd / 2), 0, 0});
    views[i].pose.orientation = head.orientation;
    views[i].pose.position = {head.position.x + eye.x, head.position.y + eye.y,
                              head.position.z + eye.z};
    views[i].fov = i == 0 ? XrFovf{kFov[0], kFov[1], kFov[2], kFov[3]}
                          : XrFovf{-kFov[1], -kFov[0], kFov[2], kFov[3]};
    g.located[i] = views[i];
  }
  return XR_SUCCESS;
}

XrResult XRAPI_CALL end_frame(XrSession, const XrFrameEndInfo* info) {
  if (!g.frame_begun) return fail(XR_ERROR_CALL_ORDER_INVALID, "xrEndFrame without xrBeginFrame");
  g.frame_begun = false;
  if (info->type != XR_TYPE_FRAME_END_INFO || info->displayTime <= 0) {
    return fail(XR_ERROR_TIME_INVALID, "xrEndFrame: no display time");
  }
  for (uint32_t l = 0; l < info->layerCount; ++l) {
    const auto* layer = reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[l]);
    if (layer->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION || layer->viewCount != 2) {
      return fail(XR_ERROR_LAYER_INVALID, "xrEndFrame: not a two-view projection layer");
    }
    for (uint32_t i = 0; i < 2; ++i) {
      const auto* chain = reinterpret_cast<Swapchain*>(layer->views[i].subImage.swapchain);
      if (chain == nullptr || chain->released < 0) {
        return fail(XR_ERROR_LAYER_INVALID, "xrEndFrame: a view's swapchain has no released image");
      }
    }
    if (!context_current()) {
      return fail(XR_ERROR_RUNTIME_FAILURE, "xrEndFrame: the session's context is not current");
    }
    dump(*layer, info->displayTime);
  }
  ++g.frames;
  if (const char* after = std::getenv("AMBFPLUS_XR_EXIT_AFTER")) {
    if (!g.exit_sent && g.frames >= std::atol(after)) {
      g.exit_sent = true;
      request_exit(nullptr);
    }
  }
  return XR_SUCCESS;
}

const std::map<std::string, PFN_xrVoidFunction>& functions();

XrResult XRAPI_CALL get_instance_proc_addr(XrInstance instance, const char* name,
                                           PFN_xrVoidFunction* function) {
  const auto& all = functions();
  auto it = all.find(name);
  if (it == all.end()) {
    *function = nullptr;
    return XR_ERROR_FUNCTION_UNSUPPORTED;
  }
  // Before an instance only these three may be asked for.
  if (instance == XR_NULL_HANDLE && std::strcmp(name, "xrCreateInstance") != 0 &&
      std::strcmp(name, "xrEnumerateInstanceExtensionProperties") != 0 &&
      std::strcmp(name, "xrEnumerateApiLayerProperties") != 0) {
    *function = nullptr;
    return XR_ERROR_HANDLE_INVALID;
  }
  *function = it->second;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL enumerate_layers(uint32_t, uint32_t* count, XrApiLayerProperties*) {
  *count = 0;
  return XR_SUCCESS;
}

const std::map<std::string, PFN_xrVoidFunction>& functions() {
#define FN(name, f) \
  { name, reinterpret_cast<PFN_xrVoidFunction>(f) }
  static const std::map<std::string, PFN_xrVoidFunction> all{
      FN("xrGetInstanceProcAddr", get_instance_proc_addr),
      FN("xrEnumerateApiLayerProperties", enumerate_layers),
      FN("xrEnumerateInstanceExtensionProperties", enumerate_extensions),
      FN("xrCreateInstance", create_instance),
      FN("xrDestroyInstance", destroy_instance),
      FN("xrGetInstanceProperties", instance_properties),
      FN("xrResultToString", result_to_string),
      FN("xrGetSystem", get_system),
      FN("xrGetSystemProperties", system_properties),
      FN("xrEnumerateViewConfigurationViews", view_configuration_views),
      FN("xrEnumerateEnvironmentBlendModes", blend_modes),
      FN("xrGetOpenGLGraphicsRequirementsKHR", gl_requirements),
      FN("xrCreateSession", create_session),
      FN("xrDestroySession", destroy_session),
      FN("xrPollEvent", poll_event),
      FN("xrBeginSession", begin_session),
      FN("xrEndSession", end_session),
      FN("xrRequestExitSession", request_exit),
      FN("xrCreateReferenceSpace", create_space),
      FN("xrDestroySpace", destroy_space),
      FN("xrEnumerateSwapchainFormats", swapchain_formats),
      FN("xrCreateSwapchain", create_swapchain),
      FN("xrDestroySwapchain", destroy_swapchain),
      FN("xrEnumerateSwapchainImages", swapchain_images),
      FN("xrAcquireSwapchainImage", acquire_image),
      FN("xrWaitSwapchainImage", wait_image),
      FN("xrReleaseSwapchainImage", release_image),
      FN("xrWaitFrame", wait_frame),
      FN("xrBeginFrame", begin_frame),
      FN("xrLocateViews", locate_views),
      FN("xrEndFrame", end_frame),
  };
#undef FN
  return all;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) XrResult XRAPI_CALL
xrNegotiateLoaderRuntimeInterface(const XrNegotiateLoaderInfo* loader,
                                  XrNegotiateRuntimeRequest* request) {
  if (loader == nullptr || request == nullptr ||
      loader->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
      request->structType != XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST ||
      loader->minInterfaceVersion > 1 || loader->maxInterfaceVersion < 1) {
    return XR_ERROR_INITIALIZATION_FAILED;
  }
  request->runtimeInterfaceVersion = 1;
  request->runtimeApiVersion = XR_CURRENT_API_VERSION;
  request->getInstanceProcAddr = get_instance_proc_addr;
  return XR_SUCCESS;
}
