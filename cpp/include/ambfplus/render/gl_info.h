#pragma once

#include <string>

#include "ambfplus/export.h"

namespace ambfplus {

/// What the process's one EGL/OpenGL context runs on.
struct AMBFPLUS_API GlInfo {
  std::string vendor;        ///< GL_VENDOR
  std::string renderer;      ///< GL_RENDERER
  std::string version;       ///< GL_VERSION
  std::string glsl_version;  ///< GL_SHADING_LANGUAGE_VERSION
  std::string profile;       ///< "compatibility" or "core"
  std::string egl_vendor;    ///< EGL_VENDOR of the display
  std::string egl_version;   ///< EGL_VERSION of the display
  std::string platform;      ///< "device" (EGL device) or "surfaceless" (Mesa)
  int device_index = -1;     ///< EGL device index, -1 on the surfaceless platform
  std::string device;        ///< how the device was chosen and what it is
};

/// Creates the process's EGL context if needed and describes it. Throws RenderError naming what is
/// missing when no context can be made.
AMBFPLUS_API GlInfo gl_info();

}  // namespace ambfplus
