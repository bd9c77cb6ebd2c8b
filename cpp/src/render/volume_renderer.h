#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "ambfplus/scene/volume.h"
#include "render/gl_program.h"
#include "render/light_set.h"
#include "render/scene_renderer.h"

namespace ambfplus::render {

/// Chebyshev distance, in bricks and capped at 255, from each brick to the nearest brick whose
/// largest smoothed occupancy reaches `level` (0..255); 0 for those bricks themselves.
std::vector<std::uint8_t> brick_distances(const std::vector<std::uint8_t>& brick_max,
                                          const std::array<int, 3>& shape, double level);

/// Merges boxes in place into at most max_boxes (max_boxes >= 1), for copying each box grown
/// by margin voxels: a box joins the kept box whose union with it adds the fewest voxels to
/// their grown copies, and starts a box of its own while fewer than max_boxes are kept and
/// joining would add more than `slack` voxels. Many small edits near each other (a burr's
/// removals between two captures) then cost a few copies, and far-apart ones stay apart.
void coalesce_boxes(std::vector<VoxelBox>& boxes, int margin, std::size_t max_boxes,
                    std::int64_t slack);

/// The obscurance field of the volume looks is made at half resolution: a cell is 2 x 2 x 2
/// voxels (cell c spans voxels [2c, 2c + 2) on each axis; cells past the grid count as empty).
constexpr int kObscuranceCell = 2;
/// Its Gaussian's standard deviation and reach, in cells.
constexpr double kObscuranceSigma = 2.0;
constexpr int kObscuranceReach = 6;

/// The cells of a grid of `shape` voxels (rounded up).
std::array<int, 3> obscurance_cells(const std::array<int, 3>& shape);

/// The solid voxels (label != 0) of each cell of `cells` (0..8), read from labels packed in
/// `frame` (i fastest, `bytes` per label; the frame holds every voxel of those cells inside the
/// grid), into `counts`, the whole cell grid packed.
void count_cell_occupancy(const std::uint8_t* labels, const VoxelBox& frame, int bytes,
                          const std::array<int, 3>& shape, const VoxelBox& cells,
                          std::uint8_t* counts);

/// The share of solid voxels around each cell of `cells` (0..255), weighted by a Gaussian of
/// kObscuranceSigma cells cut at kObscuranceReach, from the cell counts of the whole grid
/// (`cell_shape`; nothing outside it is solid): packed in `cells`, i fastest. Exact for any
/// box: a box's values equal the same cells of the whole grid's.
std::vector<std::uint8_t> blur_cell_occupancy(const std::vector<std::uint8_t>& counts,
                                              const std::array<int, 3>& cell_shape,
                                              const VoxelBox& cells);

/// What the last upload of a volume sent to the GPU.
struct VolumeUpload {
  bool full = false;
  std::int64_t voxels = 0;  ///< label voxels uploaded
  double seconds = 0.0;     ///< wall time of staging and upload, derived fields included
};

/// The GPU copies of one VolumeData (smoothed occupancy, labels, brick distances, label colours,
/// and for the looks the obscurance field),
/// brought up to date with only the boxes edited since the last update. Updating has two halves:
/// stage() only copies the edited labels (with the margin their derived fields need) out of the
/// data while the world's state lock is held, upload() does everything else (the smoothed
/// occupancy and brick maxima of those boxes, brick distances, GL calls; needs a current
/// context) off the lock, so a physics thread edits the data, and never pays for the derived
/// fields, while the GPU side works. draw() too needs a current context.
class GpuVolume {
 public:
  explicit GpuVolume(std::shared_ptr<VolumeData> data);
  ~GpuVolume();
  GpuVolume(const GpuVolume&) = delete;
  GpuVolume& operator=(const GpuVolume&) = delete;

  /// Copies what changed since the last stage (everything the first time) for upload().
  void stage(double iso);
  /// Sends what was staged to the GPU (creating the textures the first time).
  void upload();
  /// Ray casts a snapshot's volume into the bound framebuffer, after the meshes and
  /// depth-tested, seen from view (world from the view's OpenCV-like frame) through projection,
  /// for the passes (shading only with rgb), changed as pass says.
  void draw(const Snapshot::Volume& volume, const Eigen::Isometry3d& view,
            const Eigen::Matrix4d& projection, unsigned passes, const LightSet& lights,
            const SurfacePass& pass);
  /// Counts the uploads that changed what the GPU holds (a shadow map drawn of an older count
  /// is out of date).
  std::int64_t generation() const { return generation_; }
  VolumeUpload last_upload() const;
  const std::shared_ptr<VolumeData>& data() const { return data_; }

 private:
  // A box of a grid, packed (i fastest), waiting for upload().
  struct Box {
    VoxelBox box;
    std::vector<std::uint8_t> bytes;
  };
  // Labels copied under the lock: the box edited, the smoothed field it changes (`grown`), the
  // bricks whose maxima that reaches and their footprints, and the labels of `frame` (a packed
  // box of the grid) from which upload() derives them.
  struct Region {
    VoxelBox edited, grown, bricks, footprints, frame;
    std::vector<std::uint8_t> labels;
  };
  // What upload() sends for a staged update.
  struct Derived {
    std::vector<Box> labels, occupancy;
    std::vector<Box> brick_max;  // boxes of the brick grid
  };
  struct Pending {
    std::vector<Region> regions;
    std::vector<std::uint8_t> colors;  // RGBA rows of 256 label ids; empty: unchanged
    int color_rows = 0;
    std::vector<std::uint8_t> intensity;  // the whole grid, 0..255, when it is new or changed
    bool drop_intensity = false;          // the grid was removed
    double level = 0.0;                   // 0..255 of the smoothed occupancy that counts as surface
    bool full = false;
    double seconds = 0.0;  // staging time
  };
  void stage_colors(Pending& pending);
  /// The labels, smoothed occupancy and brick maxima a staged region changed.
  void derive(const Region& region, int bytes, Derived& out) const;
  /// Brings the brick distances up to date with new brick maxima and uploads what changed of
  /// them.
  void update_distances(const std::vector<Box>& brick_boxes, double level, bool full);
  void create_textures();
  /// Recomputes the obscurance field over `cells` (grown by its reach) and uploads it; creates
  /// it over the whole grid the first time.
  void update_obscurance(const VoxelBox& cells);

  std::shared_ptr<VolumeData> data_;
  GLuint occupancy_ = 0, labels_ = 0, bricks_ = 0, colors_ = 0, vao_ = 0, vbo_ = 0;
  GLuint intensity_ = 0;  // the CT intensity (normalized_intensity), 0 without one
  // Staging state (touched under the world's state lock only).
  std::int64_t revision_ = -1;
  std::vector<Label> staged_table_;
  double staged_level_ = -1;
  std::int64_t staged_intensity_ = -1;  // VolumeData::intensity_revision() last staged
  std::vector<VoxelBox> boxes_;         // scratch
  // Handed from stage() to upload(), which may run on different threads.
  mutable std::mutex mutex_;
  std::vector<Pending> pending_;
  VolumeUpload last_upload_;
  // Upload state (touched under the GL context's scope only): the brick maxima as last staged,
  // the distances made of them and the level they were made for.
  std::vector<std::uint8_t> brick_max_;
  std::vector<std::uint8_t> distances_;
  double distance_level_ = -1;
  std::int64_t generation_ = 0;
  // The solid voxels of each cell (count_cell_occupancy), kept up to date by every upload, and
  // the obscurance texture made of them the first time a camera with looks draws the volume.
  std::vector<std::uint8_t> cell_counts_;
  GLuint obscurance_ = 0;
};

}  // namespace ambfplus::render
