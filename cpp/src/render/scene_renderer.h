#pragma once

#include <epoxy/gl.h>

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ambfplus/capture/frame.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/rigid_body.h"
#include "render/light_set.h"

namespace ambfplus {
class World;
class VolumeData;
struct MeshData;
}  // namespace ambfplus

namespace ambfplus::render {

class GpuVolume;
struct VolumeUpload;

/// A mesh in GPU buffers.
struct GpuMesh {
  GLuint vao = 0;
  GLuint legacy_vao = 0;  // AMBF's attribute layout, made when a legacy shader first draws it
  GLuint buffers[3] = {0, 0, 0};  // positions, normals, indices
  GLsizei index_count = 0;
  int position_size = 3;
  std::shared_ptr<const MeshData> source;  // kept alive, so its address is never reused
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

/// What one camera sees at one step: everything a draw needs, copied out of the world while its
/// state lock is held, so that physics runs on while the GPU draws.
struct Snapshot {
  struct Body {
    std::shared_ptr<const MeshData> mesh;
    Eigen::Isometry3d pose;  // world from body
    Material material;
    std::optional<ShaderSpec> shader;  // the effective user shader, if any
    int id = 0;
  };
  struct Soft {
    int id = 0;
    std::vector<float> positions;                           // world frame, 3 per node
    const std::vector<std::uint32_t>* triangles = nullptr;  // fixed for the body's life
    Material material;
    std::optional<ShaderSpec> shader;
  };
  struct Volume {
    GpuVolume* gpu = nullptr;
    Eigen::Isometry3d pose;  // world from volume frame
    double iso = 0.5;
    float specular = 0.0f, shininess = 1.0f;
    int id = 0;
    bool skipping = true;
  };

  int camera_id = 0;
  std::string camera_name;
  int width = 0, height = 0;
  Eigen::Isometry3d camera_pose;  // world from camera
  Eigen::Matrix4d projection;
  std::array<float, 3> background{};
  std::optional<ShaderSpec> preprocessing;
  unsigned passes = 0;
  double time = 0.0;
  std::optional<LightSet> lights;  // in the camera frame
  std::vector<Body> bodies;
  std::vector<Soft> softs;
  std::vector<Volume> volumes;
};

/// Draws a world's bodies for its cameras into off-screen buffers and reads them back. Owns the
/// GL objects of one world. A render copies what it needs out of the world under the world's
/// state lock (World::lock_state) and draws after releasing it; GL work takes the process's
/// context (Context::Scope).
class SceneRenderer {
 public:
  explicit SceneRenderer(World& world);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Renders camera's view into buffers (null ones are skipped) and fills frame's time, step,
  /// intrinsics and pose, all of one simulation step.
  void render(const Camera& camera, const CaptureBuffers& buffers, Frame& frame);
  /// Renders camera's view (those passes) and leaves it in the camera's render target, for a
  /// window to show; fills frame as render does. Needs no Scope.
  const RenderTarget& render_to_target(const Camera& camera, unsigned passes, Frame& frame);
  /// The camera's render target as its last render_to_target left it; nullptr before one.
  const RenderTarget* last_target(const Camera& camera);
  /// What the last upload of this volume data sent to the GPU (nullptr before its first draw).
  std::optional<VolumeUpload> last_upload(const VolumeData* data) const;

 private:
  /// Copies the camera's view out of the world (the caller holds the world's state lock).
  void take(const Camera& camera, unsigned passes, Snapshot& snapshot);
  /// Draws a snapshot and leaves it in the GPU (needs a Context::Scope).
  void draw(const Snapshot& snapshot);
  /// Reads the last draw of a snapshot's camera into buffers.
  void read(const Snapshot& snapshot, const CaptureBuffers& buffers);
  /// Copies the camera's view out of the world (under its lock) and fills frame.
  void snapshot(const Camera& camera, unsigned passes, Snapshot& snapshot, Frame& frame);

  GpuMesh& mesh_for(const std::shared_ptr<const MeshData>& mesh);
  /// The soft body's GPU mesh, its vertices refreshed from the snapshot (normals recomputed).
  GpuMesh& soft_mesh_for(const Snapshot::Soft& soft);
  RenderTarget& target_for(const Snapshot& snapshot);
  /// Colours, into one attachment over the main pass, the meshes shader_of gives a user's
  /// shader for (nullptr: keep the engine's colours).
  template <typename ShaderOf>
  void overlay(const Snapshot& snapshot, GLenum attachment, ShaderOf shader_of);

  World& world_;
  std::map<const MeshData*, GpuMesh> meshes_;
  std::map<int, GpuMesh> soft_meshes_;   // by soft body id; vertices change every frame
  std::vector<float> soft_scratch_;      // positions then normals of one soft body
  std::map<int, RenderTarget> targets_;  // by camera id
  mutable std::mutex volumes_mutex_;     // volumes_ grows during takes, which may overlap draws
  std::map<const VolumeData*, std::unique_ptr<GpuVolume>> volumes_;
};

}  // namespace ambfplus::render
