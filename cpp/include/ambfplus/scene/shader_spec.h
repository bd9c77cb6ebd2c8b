#pragma once

// A shader a body, model, world or camera asks to be drawn with: plain scene data, which the
// render area compiles (the scene itself draws nothing).

#include <string>

#include "ambfplus/export.h"

namespace ambfplus {

/// A pair of GLSL files that colour a surface in place of the engine's own shader (AMBF's
/// `shaders: {path, vertex, fragment}`). Either dialect works:
/// - legacy GLSL 1.x with compatibility built-ins (`gl_ModelViewMatrix`, `ftransform()`,
///   `gl_FrontMaterial`, `gl_FrontLightProduct`, ...), as AMBF's files are written, fed as AMBF
///   feeds them (cpp/README.md, "Shaders");
/// - modern GLSL (#version 140 or later without those built-ins) with the engine's documented
///   attributes and uniforms.
/// A shader only colours: depth, ids, labels and voxels always come from the geometry.
struct AMBFPLUS_API ShaderSpec {
  std::string vertex;    ///< path of the vertex shader
  std::string fragment;  ///< path of the fragment shader

  /// Both empty: the engine's own shader.
  bool builtin() const { return vertex.empty() && fragment.empty(); }
  bool operator==(const ShaderSpec& o) const {
    return vertex == o.vertex && fragment == o.fragment;
  }
};

}  // namespace ambfplus
