#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/volume.h"
#include "render/gl_program.h"
#include "render/light_set.h"

namespace ambfplus::render {

/// Chebyshev distance, in bricks and capped at 255, from each brick to the nearest brick whose
/// largest smoothed occupancy reaches `level` (0..255); 0 for those bricks themselves.
std::vector<std::uint8_t> brick_distances(const std::vector<std::uint8_t>& brick_max,
                                          const std::array<int, 3>& shape, double level);

/// What the last sync of a volume sent to the GPU.
struct VolumeUpload {
  bool full = false;
  std::int64_t voxels = 0;  ///< label voxels uploaded
  double seconds = 0.0;     ///< wall time of the sync, derived fields included
};

/// The GPU copies of one VolumeData (smoothed occupancy, labels, brick distances, label colours),
/// brought up to date by uploading only the box edited since the last sync. Needs a current
/// context in every call.
class GpuVolume {
 public:
  explicit GpuVolume(std::shared_ptr<VolumeData> data);
  ~GpuVolume();
  GpuVolume(const GpuVolume&) = delete;
  GpuVolume& operator=(const GpuVolume&) = delete;

  /// Uploads what changed since the last sync (everything the first time).
  void sync(double iso);
  /// Ray casts the volume into the bound framebuffer (after the meshes, depth-tested).
  /// Ray casts the volume for the CapturePass bits asked for (shading only with rgb).
  void draw(const Volume& volume, const Camera& camera, const Eigen::Isometry3d& camera_from_world,
            const LightSet& lights, unsigned passes);
  const VolumeUpload& last_upload() const { return last_upload_; }

 private:
  void upload_box(const VoxelBox& box);
  void update_distances(const VoxelBox& changed, double level, bool full);
  void upload_colors();

  std::shared_ptr<VolumeData> data_;
  GLuint occupancy_ = 0, labels_ = 0, bricks_ = 0, colors_ = 0, vao_ = 0, vbo_ = 0;
  std::int64_t revision_ = -1;
  double brick_level_ = -1;
  std::vector<std::uint8_t> distances_;  // what the brick texture holds
  std::vector<Label> uploaded_table_;
  VolumeUpload last_upload_;
};

}  // namespace ambfplus::render
