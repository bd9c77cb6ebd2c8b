#pragma once

#include <array>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/haptics/mesh_collider.h"
#include "ambfplus/haptics/voxel_collider.h"

namespace ambfplus {

/// Friction between a cursor and the surface it slides on.
struct AMBFPLUS_API Friction {
  double static_coefficient = 0.0;   ///< mu_s: the proxy sticks while the goal stays in its cone
  double dynamic_coefficient = 0.0;  ///< mu_d: the cone it slides on once slipping
};

/// A finger-proxy cursor: a sphere (the proxy) that follows a goal (where the device puts it) but
/// never enters the volume's solid. Within one update it can meet up to three surfaces: it stops
/// on the first, slides in that plane, then along the crease of two, and stops in the corner of
/// three. Planes are the smoothed occupancy's (the surface as rendered, so on a voxelised curve the
/// proxy follows the curve, not its staircase), and sliding tolerates the micrometre bumps the
/// voxel spheres leave between their centres. Rigid meshes and planes (a MeshCollider) stop it
/// the same way, at their exact triangles. All positions are in the volume frame.
class AMBFPLUS_API ProxyCursor {
 public:
  explicit ProxyCursor(double radius = 0.001);

  double radius() const { return radius_; }
  void set_radius(double r) { radius_ = r; }
  /// Places proxy and goal at p, forgetting contacts.
  void reset(const Eigen::Vector3d& p);

  /// Moves the proxy towards goal, against the collider. Sweeps only, so a goal that moves
  /// through a wall in one step cannot tunnel. meshes, if given, are in the volume frame too.
  void update(const VoxelCollider& collider, const Eigen::Vector3d& goal,
              const Friction& friction = {}, const MeshCollider* meshes = nullptr);

  const Eigen::Vector3d& proxy() const { return proxy_; }
  const Eigen::Vector3d& goal() const { return goal_; }
  /// Surfaces in contact after the last update (0..3) and their outward normals (of the smoothed
  /// occupancy, as the surface is rendered).
  int contacts() const { return contacts_; }
  const Eigen::Vector3d& normal(int i) const { return normals_[i]; }
  /// The voxel touched by contact i, or {-1, -1, -1} for a mesh.
  const std::array<int, 3>& contact_voxel(int i) const { return voxels_[i]; }
  /// Sum of the contact normals, unit (zero without contact).
  Eigen::Vector3d mean_normal() const;
  /// The surface voxels gathered around the proxy by the last update.
  const SurfacePatch& patch() const { return patch_; }

 private:
  // Moves towards target with friction in the plane(s) already met.
  void slide(const Eigen::Vector3d& target, const Friction& friction);
  void push_out(const VoxelCollider& collider);
  Eigen::Vector3d surface_normal(const VoxelCollider& collider, const SweepHit& hit,
                                 const Eigen::Vector3d& cursor) const;
  // The contact whose surface has normal n (within 25 degrees), or -1.
  int same_surface(const Eigen::Vector3d& n) const;

  double radius_;
  SurfacePatch patch_;
  // Normals computed in this update, reused for touches within half a voxel of each other.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> normal_cache_;
  Eigen::Vector3d proxy_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal_ = Eigen::Vector3d::Zero();
  int contacts_ = 0;
  int previous_contacts_ = 0;
  std::array<Eigen::Vector3d, 3> normals_;
  std::array<std::array<int, 3>, 3> voxels_{};
  bool slipping_ = true;
  // What push_out last checked against: solid can appear under the proxy only through edits
  // made outside the collider, or by the cursor growing.
  std::int64_t checked_edits_ = -1;
  double checked_radius_ = -1;
};

}  // namespace ambfplus
