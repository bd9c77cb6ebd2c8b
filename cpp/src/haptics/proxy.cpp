#include "ambfplus/haptics/proxy.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace ambfplus {
namespace {

// How far a proxy stops short of a surface, relative to its radius: far below a voxel, far
// above rounding.
constexpr double kBackoff = 1e-3;
// Normals average the occupancy over a ball this many voxel radii wide (6 voxels: normals of a
// voxelised sphere within 2 degrees).
constexpr double kNormalBall = 12.0;
// Hits whose normals are within 25 degrees of a plane already met belong to that surface.
const double kSameSurface = std::cos(25.0 * 3.14159265358979323846 / 180.0);
// Sweeps per update at most (bumps, then creases and corners).
constexpr int kMaxSweeps = 12;

}  // namespace

ProxyCursor::ProxyCursor(double radius) : radius_(radius) {
  normals_.fill(Eigen::Vector3d::Zero());
}

void ProxyCursor::reset(const Eigen::Vector3d& p) {
  proxy_ = goal_ = p;
  contacts_ = 0;
  previous_contacts_ = 0;
  slipping_ = true;
  checked_edits_ = -1;
}

Eigen::Vector3d ProxyCursor::mean_normal() const {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int i = 0; i < contacts_; ++i) n += normals_[i];
  return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
}

void ProxyCursor::push_out(const VoxelCollider& collider) {
  // Edits made elsewhere (or a cursor that grew) can leave the proxy inside solid: move it out
  // along the surface normal, a few tries at most. Nothing else can, so the check runs only then.
  if (collider.outside_edits() == checked_edits_ && radius_ <= checked_radius_) return;
  checked_edits_ = collider.outside_edits();
  checked_radius_ = radius_;
  for (int attempt = 0; attempt < 4; ++attempt) {
    const SweepHit inside = collider.sweep(proxy_, proxy_, radius_);
    if (!inside.hit) return;
    Eigen::Vector3d n = collider.normal(inside.voxel_center, kNormalBall * collider.voxel_radius());
    if (n.norm() == 0) n = (proxy_ - inside.voxel_center).normalized();
    const double overlap =
        radius_ + collider.voxel_radius() - (proxy_ - inside.voxel_center).norm();
    proxy_ += n * std::max(overlap, 0.0) * 1.01 + n * kBackoff * radius_;
  }
}

void ProxyCursor::slide(const Eigen::Vector3d& target, const Friction& friction) {
  if (friction.static_coefficient <= 0 && friction.dynamic_coefficient <= 0) {
    proxy_ = target;
    return;
  }
  // The goal pressed into the surface by `depth` may pull the proxy only as far as the rim of a
  // cone of half-angle atan(mu) around it; inside, the proxy sticks.
  const Eigen::Vector3d n = mean_normal();
  const double depth = std::max(0.0, -(goal_ - proxy_).dot(n));
  const Eigen::Vector3d to_proxy = proxy_ - goal_;
  const double angle =
      to_proxy.norm() > 0 ? std::acos(std::clamp(to_proxy.normalized().dot(n), -1.0, 1.0)) : 0.0;
  if (friction.dynamic_coefficient > friction.static_coefficient) {
    slipping_ = true;
  } else if (slipping_) {
    slipping_ = angle >= 0.6 * std::atan(friction.dynamic_coefficient);
  } else {
    slipping_ = angle > std::atan(friction.static_coefficient);
  }
  const double mu = slipping_ ? friction.dynamic_coefficient : friction.static_coefficient;
  const double allowed = mu * depth;
  const Eigen::Vector3d offset = proxy_ - target;
  const double d = offset.norm();
  if (d > allowed) proxy_ = target + offset * (allowed / d);
}

Eigen::Vector3d ProxyCursor::surface_normal(const VoxelCollider& collider, const SweepHit& hit,
                                            const Eigen::Vector3d& cursor) const {
  // The smoothed occupancy's normal (the surface as rendered) where the cursor, centred at
  // `cursor`, touches the voxel, unless it disagrees with the voxel sphere's (a thin sliver).
  Eigen::Vector3d geometric = cursor - hit.voxel_center;
  geometric =
      geometric.norm() > 0 ? Eigen::Vector3d(geometric.normalized()) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d touch = hit.voxel_center + geometric * collider.voxel_radius();
  Eigen::Vector3d n;
  auto& cache = const_cast<ProxyCursor*>(this)->normal_cache_;
  const auto near = std::find_if(cache.begin(), cache.end(), [&](const auto& e) {
    return (e.first - touch).norm() < collider.voxel_radius();
  });
  if (near != cache.end()) {
    n = near->second;
  } else {
    n = collider.normal(touch, kNormalBall * collider.voxel_radius());
    cache.emplace_back(touch, n);
  }
  return n.dot(geometric) > 0.1 ? n : geometric;
}

int ProxyCursor::same_surface(const Eigen::Vector3d& n) const {
  for (int i = 0; i < contacts_; ++i) {
    if (normals_[i].dot(n) > kSameSurface) return i;
  }
  return -1;
}

void ProxyCursor::update(const VoxelCollider& collider, const Eigen::Vector3d& goal,
                         const Friction& friction, const MeshCollider* meshes) {
  goal_ = goal;
  push_out(collider);
  const Eigen::Vector3d last_normal = mean_normal();  // of the last update's contacts
  contacts_ = 0;
  const double backoff = kBackoff * radius_;
  // Voxel spheres leave bumps between their centres, at most s^2 / 4(r + s/2) high. Sliding
  // along surfaces already met tolerates that much, so the proxy glides over their bumps; a new
  // surface is met at the full radius.
  const double s = 2 * collider.voxel_radius();
  const double ripple = std::min(0.5 * radius_, 1.5 * s * s / (4 * (radius_ + 0.5 * s)));
  Eigen::Vector3d target = goal;
  // The first target of this step is the goal, or its projection onto a plane through the proxy,
  // which lies on the sphere whose diameter joins proxy and goal (the foot of a perpendicular
  // sees that diameter at a right angle): gather the surface within the cursor's reach of that
  // sphere once. (Sweeps that leave it, along creases, fall back to the bricks.)
  const Eigen::Vector3d offset = goal - proxy_;
  const bool pressing = previous_contacts_ > 0 && offset.dot(last_normal) < 0;
  collider.gather(proxy_ + 0.5 * offset,
                  0.5 * offset.norm() + radius_ + 4 * collider.voxel_radius(), patch_);
  const SurfacePatch& patch = patch_;
  normal_cache_.clear();
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    const Eigen::Vector3d motion = target - proxy_;
    const double length = motion.norm();
    if (length < 1e-12) break;
    const double r = contacts_ == 0 ? radius_ : radius_ - ripple;
    SweepHit hit;
    if (sweep == 0 && pressing) {
      // Pressing on: the contact is right ahead, within a short probe of the patch.
      const double probe = std::min(length, 4 * collider.voxel_radius());
      hit = collider.sweep(patch, proxy_, proxy_ + motion * (probe / length), r);
      hit.t *= probe / length;
      if (!hit.hit) hit = collider.sweep(patch, proxy_, target, r);
    } else {
      hit = collider.sweep(patch, proxy_, target, r);
    }
    Eigen::Vector3d n;
    if (hit.hit) {
      n = surface_normal(collider, hit, proxy_ + motion * hit.t);
      if (contacts_ > 0 && same_surface(n) < 0) {
        // A new surface while sliding: meet it at the full radius.
        const SweepHit full = collider.sweep(patch, proxy_, target, radius_);
        if (full.hit) {
          hit = full;
          n = surface_normal(collider, hit, proxy_ + motion * hit.t);
        }
      }
    }
    if (meshes != nullptr && meshes->parts() > 0) {
      // A mesh met first wins (at the full radius: its triangles are exact, without bumps).
      const MeshHit mesh = meshes->sweep(proxy_, target, radius_);
      if (mesh.hit && (!hit.hit || mesh.t < hit.t)) {
        hit.hit = true;
        hit.t = mesh.t;
        hit.voxel = {-1, -1, -1};
        n = mesh.normal;
      }
    }
    if (!hit.hit) {
      if (contacts_ == 0) {
        proxy_ = target;
      } else {
        slide(target, friction);
      }
      break;
    }
    // Stop short of the contact along the motion.
    const double travel = std::max(0.0, hit.t * length - backoff);
    proxy_ += motion * (travel / length);
    // A surface already met (a curve followed while sliding) updates its plane; met again
    // without having moved, it holds the proxy where it is.
    int slot = same_surface(n);
    if (slot >= 0 && travel < 1e-3 * collider.voxel_radius()) {
      normals_[slot] = n;
      break;
    }
    if (slot < 0) slot = contacts_++;
    normals_[slot] = n;
    voxels_[slot] = hit.voxel;
    if (contacts_ == 3) break;  // a corner: nowhere left to slide
    if (contacts_ == 1) {
      // Slide in the plane of the surface: the goal projected onto it (or, when the goal is
      // above it, straight towards the goal).
      const double below = (goal - proxy_).dot(normals_[0]);
      target = below < 0 ? Eigen::Vector3d(goal - below * normals_[0]) : goal;
    } else {
      // Slide along the crease of the two surfaces.
      Eigen::Vector3d line = normals_[0].cross(normals_[1]);
      if (line.norm() < 1e-6) break;
      line.normalize();
      target = proxy_ + line * (goal - proxy_).dot(line);
    }
  }
  // Free of every surface: no contact.
  if ((proxy_ - goal_).norm() < 1e-12) contacts_ = 0;
  previous_contacts_ = contacts_;
}

}  // namespace ambfplus
