#pragma once

#include <epoxy/gl.h>

#include <map>
#include <memory>
#include <vector>

#include "ambfplus/scene/camera.h"

namespace ambfplus {
class SoftBody;
class World;
class VolumeData;
struct MeshData;
}  // namespace ambfplus

namespace ambfplus::render {

class GpuVolume;
struct LightSet;
struct VolumeUpload;

/// A mesh in GPU buffers.
struct GpuMesh {
  GLuint vao = 0;
  GLuint legacy_vao = 0;  // AMBF's attribute layout, made when a legacy shader first draws it
  GLuint buffers[3] = {0, 0, 0};  // positions, normals, indices
  GLsizei index_count = 0;
  int position_size = 3;
};

/// Off-screen colour, metric-depth, id and depth-test buffers of one camera's size.
struct RenderTarget {
  // One colour attachment per capture pass (pass i on attachment i), then the depth test.
  static constexpr int kBuffers = kPassCount + 1;
  GLuint framebuffer = 0;
  // colour (RGBA8), depth (R32F), label (R16UI), instance (R32I), voxel (R32I), segmentation
  // (RGBA8), depth test (D32F)
  GLuint renderbuffers[kBuffers] = {};
  int width = 0;
  int height = 0;
};

/// Draws a world's bodies for its cameras into off-screen buffers and reads them back. Owns the
/// GL objects of one world; every call takes the process's context (Context::Scope).
class SceneRenderer {
 public:
  explicit SceneRenderer(World& world);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Renders camera's view and reads it into buffers (null ones are skipped).
  void render(const Camera& camera, const CaptureBuffers& buffers);
  /// Renders camera's view (the CapturePass bits asked for) and leaves it in the GPU.
  void draw(const Camera& camera, unsigned passes = kPassRgb | kPassDepth | kPassLabel);
  /// Reads the last draw of camera into buffers.
  void read(const Camera& camera, const CaptureBuffers& buffers);
  /// What the last sync of this volume data sent to the GPU (nullptr before its first draw).
  const VolumeUpload* last_upload(const VolumeData* data) const;

 private:
  GpuMesh& mesh_for(const MeshData* mesh);
  /// The soft body's GPU mesh, its vertices refreshed from the nodes (normals recomputed).
  GpuMesh& soft_mesh_for(const SoftBody& body);
  RenderTarget& target_for(const Camera& camera);
  /// Colours, into one attachment over the main pass, the meshes shader_of gives a user's
  /// shader for (nullptr: keep the engine's colours).
  template <typename ShaderOf>
  void overlay(const Camera& camera, const Eigen::Isometry3d& camera_from_world,
               const LightSet& lights, GLenum attachment, ShaderOf shader_of);

  World& world_;
  std::map<const MeshData*, GpuMesh> meshes_;
  std::map<int, GpuMesh> soft_meshes_;   // by soft body id; vertices change every frame
  std::vector<float> soft_scratch_;      // positions then normals of one soft body
  std::map<int, RenderTarget> targets_;  // by camera id
  std::map<const VolumeData*, std::unique_ptr<GpuVolume>> volumes_;
};

}  // namespace ambfplus::render
