#pragma once

#include <epoxy/gl.h>

#include <array>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/capture/frame.h"
#include "ambfplus/render/renderer.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/rigid_body.h"
#include "render/light_set.h"

namespace ambfplus {
class World;
class Volume;
class VolumeData;
struct MeshData;
}  // namespace ambfplus

namespace ambfplus::render {

class GpuVolume;
struct VolumeUpload;

/// A mesh in GPU buffers.
struct GpuMesh {
  GLuint vao = 0;
  Eigen::AlignedBox3d bounds;  // of the mesh's finite vertices (empty when none or homogeneous)
  GLuint legacy_vao = 0;       // AMBF's attribute layout, made when a legacy shader first draws it
  GLuint buffers[3] = {0, 0, 0};  // positions, normals, indices
  GLuint texcoords = 0;           // u, v per vertex; 0 when the mesh has none
  GLsizei index_count = 0;
  int position_size = 3;
  std::shared_ptr<const MeshData> source;  // kept alive, so its address is never reused
};

/// What supersampling reads of a capture to pick its pixels: the shaded colour (RGBA) and the
/// exact depth, label and instance passes at the pixel centres, rows bottom up.
struct EdgeInputs {
  std::vector<std::uint8_t> rgba;
  std::vector<float> depth;
  std::vector<std::uint16_t> label;
  std::vector<std::int32_t> instance;
};

/// Marks (1, else 0) the pixels whose samples may differ: where a neighbour (of the 8) shows
/// another object or label, a depth more than 1% apart, or a colour more than 25 of 255 apart in
/// a channel (shadow edges, textures, highlights).
void supersample_edges(const EdgeInputs& in, int width, int height, std::uint8_t* mask);

/// Off-screen colour, metric-depth, id and depth-test buffers of one camera's size.
struct RenderTarget {
  // One colour attachment per drawn pass (pass i on attachment i), then the depth test.
  static constexpr int kBuffers = kRenderedPassCount + 1;
  GLuint framebuffer = 0;
  // colour (RGBA8), depth (R32F), label (R16UI), instance (R32I), voxel (R32I), segmentation
  // (RGBA8), depth test (D32F)
  GLuint textures[kBuffers] = {};
  int width = 0;
  int height = 0;
  // Supersampling of the rgb pass (made when first asked for, remade for another factor). Its
  // samples lie on a lattice: for k = 2 the pixels' corners (each edge pixel takes its centre,
  // the main pass's own sample, and its four corners), for k = 3 or 4 a k x k grid per pixel.
  // The lattice's colour, depth and stencil hold the meshes' samples; the volumes' samples are
  // rays packed densely, one per fragment of the packed target.
  int factor = 0;
  GLuint samples_framebuffer = 0, samples[2] = {0, 0};  // the lattice's colour, depth-stencil
  GLuint mask = 0;                                      // per pixel, 1 where it is supersampled
  GLuint lattice_index = 0;  // per lattice point, its packed texel, or -1 (RG16I)
  // The volumes' samples' colour, depth test and places (RGBA32F, see supersample()), grown to
  // the largest packing yet.
  GLuint packed_framebuffer = 0, packed[3] = {0, 0, 0};
  int packed_width = 0, packed_height = 0;
  GLuint points_vao = 0, points_buffer = 0;  // the lattice's tiles and the pixel blocks, as points
  int stencil = 0;  // the stencil value marking this capture's samples (1..255)
};

/// A light's shadow map (kept across captures while what casts shadows stays put).
struct ShadowMap {
  GLuint texture = 0, framebuffer = 0;
  int size = 0;
  std::size_t key = 0;                                        // what it was drawn of
  Eigen::Matrix4d clip_from_world = Eigen::Matrix4d::Zero();  // the light's clip space
  Eigen::Vector2d texel = Eigen::Vector2d::Zero();  // a texel's size, x + y * clip w (metres)
};

/// How one drawing of a snapshot's surfaces differs from the camera's main one: extra shader
/// defines and uniforms (shadow maps, the supersampling mask), or parallel rays (a directional
/// light's shadow map).
struct SurfacePass {
  std::string defines;
  std::function<void(Program&)> setup;  // after the program's own uniforms
  bool orthographic = false;            // volumes: parallel rays along the view's z
  bool meshes = true, volumes = true;   // what is drawn
  // Volumes cast supersampling's rays, one per fragment of the packed target in one triangle
  // over it (supersample_packed.vert), rather than being drawn as their boxes.
  bool packed = false;
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
    std::string texture;  // the diffuse texture's file, "" for none
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
    bool looks = false;  // the camera's Camera::looks, for the rgb pass
  };

  int camera_id = 0;
  std::string camera_name;
  int width = 0, height = 0;
  Eigen::Isometry3d camera_pose;  // world from camera
  Eigen::Matrix4d projection;
  std::array<float, 3> background{};
  std::optional<ShaderSpec> preprocessing;
  unsigned passes = 0;
  bool shadows = false;
  int antialiasing = 1;
  double time = 0.0;
  std::optional<LightSet> lights;  // in the camera frame
  std::vector<Body> bodies;
  std::vector<Soft> softs;
  std::vector<Volume> volumes;
};

/// Draws a world's bodies for its cameras into off-screen buffers and reads them back. Owns the
/// GL objects of one world: per camera its target, per soft body and per volume their buffers
/// (by object id), and per mesh its buffers (shared by the bodies drawing it, kept while one
/// does). An object leaving the world queues its resources for release at the next render (GL
/// work needs the context). A render copies what it needs out of the world under the world's
/// state lock (World::lock_state) and draws after releasing it; GL work takes the process's
/// context (Context::Scope).
class SceneRenderer : public Renderer {
 public:
  explicit SceneRenderer(World& world);
  ~SceneRenderer() override;
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // System
  const char* name() const override { return "renderer"; }
  unsigned stages() const override { return 0; }
  void object_removed(Object& object) override;
  /// Releases every GL object (the world is going away).
  void detach_all() override;

  void render(const Camera& camera, const CaptureBuffers& buffers, const PoseRequest& poses,
              Frame& frame) override;
  /// Renders camera's view (those passes) and leaves it in the camera's render target, for a
  /// window to show; fills frame as render does. Needs no Scope.
  const RenderTarget& render_to_target(const Camera& camera, unsigned passes, Frame& frame);
  /// The camera's render target as its last render_to_target left it; nullptr before one.
  const RenderTarget* last_target(const Camera& camera);
  /// What the last upload of this volume sent to the GPU (nullptr before its first draw).
  std::optional<VolumeUpload> last_upload(const Volume& volume) const;
  /// GL objects held: meshes, soft meshes, targets, volumes (for tests of their release).
  std::array<std::size_t, 4> resource_counts() const;

 private:
  /// Copies the camera's view out of the world (the caller holds the world's state lock).
  void take(const Camera& camera, unsigned passes, Snapshot& snapshot);
  /// The GPU side of a volume, made (or made afresh for other data) on first use.
  GpuVolume& gpu_volume(const Volume& volume);
  /// Copies what changed of the world's volumes in a hold of the world's lock of its own, so
  /// that the snapshot's hold, which must copy the volumes again, copies only what changed in
  /// between: a real-time loop steps between two short holds rather than waiting for a long one.
  void stage_volumes();
  /// Draws a snapshot and leaves it in the GPU (needs a Context::Scope).
  void draw(const Snapshot& snapshot);
  /// Reads the last draw of a snapshot's camera into buffers.
  void read(const Snapshot& snapshot, const CaptureBuffers& buffers);
  /// Copies the camera's view and the poses asked for out of the world (under its lock) and
  /// fills frame.
  void snapshot(const Camera& camera, unsigned passes, const PoseRequest& poses, Snapshot& snapshot,
                Frame& frame);
  /// Draws the snapshot's meshes and volumes with `program` (the mesh shader, in use, its
  /// per-camera uniforms set) from the view (pose, projection), for the passes.
  void draw_surfaces(const Snapshot& snapshot, Program& program, const Eigen::Isometry3d& view,
                     const Eigen::Matrix4d& projection, unsigned passes, const SurfacePass& pass);
  /// Brings the shadow maps of the snapshot's shadow casters up to date (drawn again only when
  /// what they show changed) and gives their uniforms for the snapshot's camera.
  ShadowUniforms shadow_maps(const Snapshot& snapshot);
  /// Supersamples the rgb pass of the last draw where its passes show edges or contrast.
  void supersample(const Snapshot& snapshot, RenderTarget& target, const SurfacePass& shading);
  /// Frees what objects that left the world used (needs a Context::Scope).
  void release_unused();
  void release_all();

  GpuMesh& mesh_for(const std::shared_ptr<const MeshData>& mesh);
  /// The soft body's GPU mesh, its vertices refreshed from the snapshot (normals recomputed).
  GpuMesh& soft_mesh_for(const Snapshot::Soft& soft);
  RenderTarget& target_for(const Snapshot& snapshot);
  /// The GL texture of an image file (read on first use, kept for the renderer's life); 0 when
  /// the body has none or the file cannot be read (logged once).
  GLuint texture_for(const std::string& path);
  /// Colours, into one attachment over the main pass, the meshes shader_of gives a user's
  /// shader for (nullptr: keep the engine's colours).
  template <typename ShaderOf>
  void overlay(const Snapshot& snapshot, GLenum attachment, ShaderOf shader_of);

  World& world_;
  std::map<const MeshData*, GpuMesh> meshes_;   // each keeps its source alive: no address reuse
  std::map<int, GpuMesh> soft_meshes_;          // by soft body id; vertices change every frame
  std::vector<float> soft_scratch_;             // positions then normals of one soft body
  std::map<int, RenderTarget> targets_;         // by camera id
  std::map<std::string, GLuint> textures_;      // by image file
  std::map<int, ShadowMap> shadow_maps_;        // by light id
  EdgeInputs edge_inputs_;                      // scratch: what picks them
  std::vector<std::uint8_t> supersample_mask_;  // scratch: the pixels to supersample
  std::vector<std::uint8_t> lattice_needed_;    // scratch: the lattice points to sample
  std::vector<std::int16_t> lattice_index_;     // scratch: lattice_index's values
  std::vector<float> packed_where_;             // scratch: the packed samples' places
  std::vector<float> supersample_points_;       // scratch: lattice tiles, then pixel blocks
  mutable std::mutex volumes_mutex_;  // volumes_ grows during takes, which may overlap draws
  std::map<int, std::unique_ptr<GpuVolume>> volumes_;  // by volume id
  // Ids of objects that left the world, and whether a mesh may have lost its last body;
  // released at the next render (guarded by volumes_mutex_).
  std::vector<int> released_ids_;
  bool meshes_to_check_ = false;
};

}  // namespace ambfplus::render
