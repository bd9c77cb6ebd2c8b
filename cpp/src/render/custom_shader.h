#pragma once

#include <epoxy/gl.h>

#include <Eigen/Geometry>

#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/shader_spec.h"
#include "render/gl_program.h"

namespace ambfplus {
class Model;
class World;
}  // namespace ambfplus

namespace ambfplus::render {

struct GpuMesh;
struct LightSet;

/// The ambient intensity of CHAI3D's lights, which AMBF never changes: its preprocessing shader
/// draws material ambient times this.
constexpr float kAmbfLightAmbient = 0.4f;

/// How a user's shader is fed (cpp/README.md, "Shaders").
enum class ShaderDialect {
  kLegacy,  ///< GLSL 1.x compatibility built-ins, AMBF's attribute names and samplers
  kModern,  ///< the engine's attributes (a_position, a_normal) and uniforms
};

/// A user's shader, compiled, and the dialect it speaks.
struct UserShader {
  Program* program = nullptr;
  ShaderDialect dialect = ShaderDialect::kModern;
};

/// The shader a surface is drawn with: its own, else its model's, else its world's; nullptr
/// for the engine's own.
const ShaderSpec* effective_shader(const Material& material, const Model& model,
                                   const World& world);

/// The program of a shader spec for this light combination, compiled once per process; nullptr
/// when it cannot run (a missing file, a compile or link error), reported once as a warning, so
/// that the caller keeps the engine's own colours. Needs a Context::Scope.
const UserShader* user_shader(const ShaderSpec& spec, const LightSet& lights);

/// Draws meshes with users' shaders into one colour attachment over a camera's finished main
/// pass. Only colour is written: a fragment lands where its surface is the visible one (the
/// depth test against the main pass, nudged towards the camera by a polygon offset), so depth,
/// ids and labels stay those of the geometry. Legacy shaders get AMBF's fixed-function state in
/// the OpenGL eye frame (looking down -z); modern ones the engine's uniforms. Restores the main
/// pass's state when destroyed.
class ShaderOverlay {
 public:
  /// projection: clip from camera (OpenCV frame); lights in the camera frame; time: simulation
  /// seconds (modern shaders' u_time).
  ShaderOverlay(const Eigen::Matrix4d& projection, int width, int height, const LightSet& lights,
                double time, GLenum attachment);
  ~ShaderOverlay();
  ShaderOverlay(const ShaderOverlay&) = delete;
  ShaderOverlay& operator=(const ShaderOverlay&) = delete;

  /// Draws mesh with shader; model_view is camera (OpenCV frame) from object; texture (0 for
  /// none) is the diffuse map (unit 0, `diffuseMap`, with `uTextureEnabled` set).
  void draw(const UserShader& shader, GpuMesh& mesh, const Eigen::Isometry3d& model_view,
            const Material& material, int id, GLuint texture = 0);

 private:
  void begin(const UserShader& shader);

  Eigen::Matrix4f projection_;
  int width_, height_;
  const LightSet& lights_;
  double time_;
  const UserShader* current_ = nullptr;
};

}  // namespace ambfplus::render
