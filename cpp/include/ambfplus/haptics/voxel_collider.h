#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// The first contact of a sphere swept along a segment.
struct AMBFPLUS_API SweepHit {
  bool hit = false;
  double t = 1.0;                     ///< fraction of the segment travelled before contact, 0..1
  std::array<int, 3> voxel{0, 0, 0};  ///< the voxel touched first
  Eigen::Vector3d voxel_center = Eigen::Vector3d::Zero();  ///< volume frame
};

/// The surface voxels near a point, gathered once so that several sweeps in one haptic step test
/// a short list instead of walking bricks again.
struct AMBFPLUS_API SurfacePatch {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;  ///< holds every surface voxel whose centre is within this of `centre`
  std::vector<double> x, y, z;  ///< voxel centres, volume frame
  std::vector<std::array<int, 3>> voxels;
  /// Whether a sphere of radius R swept from a to b can only touch voxels the patch holds.
  bool covers(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double R) const {
    return (a - centre).norm() + R <= radius && (b - centre).norm() + R <= radius;
  }
};

/// Collision queries of spheres against a volume's solid voxels, for haptics.
///
/// Each solid voxel is a sphere of radius half a voxel at its centre, so flat faces of voxels are
/// flat to well under a micrometre for cursors much larger than a voxel. Only surface voxels
/// (solid, with an empty face neighbour) can be touched first by a sphere coming from outside,
/// so a query gathers them from 8^3 bricks that hold any, near the swept segment, and never scans
/// the cube of voxels around the cursor. Removals made through the collider update its bitmaps
/// voxel by voxel; other edits of the volume are picked up by sync().
class AMBFPLUS_API VoxelCollider {
 public:
  explicit VoxelCollider(std::shared_ptr<VolumeData> data);

  const std::shared_ptr<VolumeData>& data() const { return data_; }
  /// Radius of the sphere each voxel is, metres.
  double voxel_radius() const { return rho_; }

  /// Rebuilds the bitmaps where the volume was edited by others since the last sync.
  void sync();
  /// Counts the syncs that found edits made by others (which may have added solid anywhere).
  std::int64_t outside_edits() const { return outside_edits_; }

  /// First contact of a sphere of radius r moving from a to b (volume frame). A sphere that
  /// already overlaps a voxel at a touches it at t = 0.
  SweepHit sweep(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) const;
  /// Surface voxels whose centres lie within radius of c, for sweeps in a small region.
  SurfacePatch gather(const Eigen::Vector3d& c, double radius) const;
  /// The same into an existing patch, reusing its memory.
  void gather(const Eigen::Vector3d& c, double radius, SurfacePatch& patch) const;
  /// sweep() against a patch (falls back to the bricks when the patch does not cover the sweep).
  SweepHit sweep(const SurfacePatch& patch, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 double r) const;
  /// The same answer found the original's way: march the segment a voxel at a time and test
  /// every solid voxel of the cube around each step (for benchmarks).
  SweepHit sweep_full_cube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) const;

  /// Outward surface normal at p (volume frame): the gradient of the occupancy smoothed over a
  /// ball of `radius` metres. Zero where the neighbourhood is all solid or all empty.
  Eigen::Vector3d normal(const Eigen::Vector3d& p, double radius) const;

  /// Solid voxels whose centres lie within radius of c, nearest first.
  std::vector<std::array<int, 3>> solid_within(const Eigen::Vector3d& c, double radius) const;
  /// Surface voxels whose centres lie within radius of c (gathered from bricks, in no order).
  /// Near a sphere that does not overlap the solid these are all the solid voxels there are.
  std::vector<std::array<int, 3>> surface_within(const Eigen::Vector3d& c, double radius) const;

  /// Clears voxels through the volume (one edit, kind "drill", logged with their labels) and
  /// updates the bitmaps. Returns the labels they had.
  std::vector<std::uint16_t> remove(const std::vector<std::array<int, 3>>& voxels);

  /// Voxels tested by queries since the last reset (for tests of how much a query looks at).
  std::int64_t voxels_tested() const { return tested_; }
  void reset_counters() { tested_ = 0; }

  bool solid(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < shape_[0] && j < shape_[1] && k < shape_[2] &&
           data_->label(i, j, k) != 0;
  }
  bool surface(int i, int j, int k) const;

 private:
  void rebuild(const VoxelBox& box);
  // Calls f(i, j, k, centre) for each surface voxel in bricks near the capsule a-b of radius R.
  template <typename F>
  void for_surface_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double R, F&& f) const;
  void refresh_surface(int i, int j, int k);
  std::size_t brick_index(int bi, int bj, int bk) const;
  // Segment a->b against the sphere of radius R at c: entry fraction, or > 1 when missed.
  static double enter(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double length,
                      const Eigen::Vector3d& c, double R);

  std::shared_ptr<VolumeData> data_;
  std::array<int, 3> shape_;
  std::array<int, 3> bricks_;
  Eigen::Vector3d voxel_size_;
  double rho_;
  std::vector<std::uint64_t> surface_;        // per brick: 8 words of 64 bits (z-slices of 8x8)
  std::vector<std::uint16_t> surface_count_;  // per brick
  std::int64_t revision_ = -1;
  std::int64_t outside_edits_ = 0;
  mutable std::int64_t tested_ = 0;
};

}  // namespace ambfplus
