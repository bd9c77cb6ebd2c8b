#include "ambfplus/haptics/mesh_collider.h"
#include "ambfplus/errors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ambfplus {
namespace {

// The point of triangle (p0, p1, p2) nearest q (the standard region test on barycentrics).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& q, const Eigen::Vector3d& p0,
                                    const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
  const Eigen::Vector3d ab = p1 - p0, ac = p2 - p0, ap = q - p0;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return p0;
  const Eigen::Vector3d bp = q - p1;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return p1;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return p0 + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = q - p2;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return p2;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return p0 + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return p1 + (p2 - p1) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denom = 1.0 / (va + vb + vc);
  return p0 + ab * (vb * denom) + ac * (vc * denom);
}

// Smallest t in [0, length] where the point a + t d is within R of the segment p-q (a capsule),
// or infinity.
double enter_capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double length,
                     const Eigen::Vector3d& p, const Eigen::Vector3d& q, double R) {
  double best = std::numeric_limits<double>::infinity();
  // The cylinder around the segment: |(a + t d - p) x e|^2 = R^2 |e|^2 with the foot inside.
  const Eigen::Vector3d e = q - p, m = a - p;
  const double ee = e.squaredNorm();
  const Eigen::Vector3d md = d * ee - e * d.dot(e), mm = m * ee - e * m.dot(e);
  const double A = md.squaredNorm(), B = 2 * md.dot(mm), C = mm.squaredNorm() - R * R * ee * ee;
  const double disc = B * B - 4 * A * C;
  if (A > 1e-30 && disc >= 0) {
    const double t = (-B - std::sqrt(disc)) / (2 * A);
    const double s = (m + t * d).dot(e) / ee;
    if (t >= 0 && t <= length && s >= 0 && s <= 1) best = t;
  }
  // Its two ends.
  for (const Eigen::Vector3d& c : {p, q}) {
    const Eigen::Vector3d w = a - c;
    const double b = w.dot(d), cc = w.squaredNorm() - R * R, dd = b * b - cc;
    if (dd < 0 || b >= 0) continue;
    const double t = -b - std::sqrt(dd);
    if (t >= 0 && t <= length) best = std::min(best, t);
  }
  return best;
}

}  // namespace

int MeshCollider::add_mesh(const MeshData& mesh) {
  if (mesh.position_size != 3) {
    throw ArgumentError("MeshCollider: mesh positions must have 3 coordinates");
  }
  Part part;
  auto vertex = [&](std::uint32_t i) {
    if (i >= mesh.vertex_count()) {
      throw ArgumentError("MeshCollider: triangle index " + std::to_string(i) +
                          " past the last vertex " + std::to_string(mesh.vertex_count()));
    }
    return Eigen::Vector3d(mesh.positions[3 * i], mesh.positions[3 * i + 1],
                           mesh.positions[3 * i + 2]);
  };
  // Groups of at most 64 triangles keep the boxes tight.
  const std::size_t triangles = mesh.triangle_count();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::size_t first = 0; first < triangles; first += 64) {
    Group g;
    g.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    g.hi = -g.lo;
    for (std::size_t t = first; t < std::min(triangles, first + 64); ++t) {
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d p = vertex(mesh.indices[3 * t + k]);
        g.v.push_back(p);
        g.lo = g.lo.cwiseMin(p);
        g.hi = g.hi.cwiseMax(p);
      }
    }
    lo = lo.cwiseMin(g.lo);
    hi = hi.cwiseMax(g.hi);
    part.groups.push_back(std::move(g));
  }
  if (triangles > 0) {
    part.centre = 0.5 * (lo + hi);
    part.bound = 0.5 * (hi - lo).norm();
  }
  parts_.push_back(std::move(part));
  return parts() - 1;
}

int MeshCollider::add_plane() {
  Part part;
  part.plane = true;
  parts_.push_back(std::move(part));
  return parts() - 1;
}

void MeshCollider::set_pose(int part, const Eigen::Isometry3d& frame_from_part) {
  Part& p = parts_.at(part);
  p.pose = frame_from_part;
  p.inverse = frame_from_part.inverse();
}

void MeshCollider::sweep_part(const Part& part, const Eigen::Vector3d& a, const Eigen::Vector3d& d,
                              double length, double r, double& best_t,
                              Eigen::Vector3d& best_point) const {
  auto consider = [&](double t, const Eigen::Vector3d& point) {
    if (t < best_t) {
      best_t = t;
      best_point = point;
    }
  };
  // Moving further in: the direction has a component into the surface (beyond rounding).
  constexpr double kInward = -1e-9;
  if (part.plane) {
    const double height = a.z();
    if (height <= r) {
      if (d.z() < kInward) consider(0.0, Eigen::Vector3d(a.x(), a.y(), 0.0));
      return;
    }
    if (d.z() < 0) {
      const double t = (r - height) / d.z();
      if (t <= length) consider(t, Eigen::Vector3d(a.x() + t * d.x(), a.y() + t * d.y(), 0.0));
    }
    return;
  }
  const Eigen::Vector3d b = a + length * d;
  const Eigen::Vector3d lo = a.cwiseMin(b) - Eigen::Vector3d::Constant(r);
  const Eigen::Vector3d hi = a.cwiseMax(b) + Eigen::Vector3d::Constant(r);
  for (const Group& g : part.groups) {
    if ((g.lo.array() > hi.array()).any() || (g.hi.array() < lo.array()).any()) continue;
    for (std::size_t i = 0; i + 2 < g.v.size(); i += 3) {
      const Eigen::Vector3d &p0 = g.v[i], &p1 = g.v[i + 1], &p2 = g.v[i + 2];
      // Already touching: blocked only when moving further in.
      const Eigen::Vector3d near = closest_on_triangle(a, p0, p1, p2);
      const Eigen::Vector3d out = a - near;
      if (out.squaredNorm() <= r * r) {
        if (length > 0 && out.dot(d) < kInward * out.norm()) consider(0.0, near);
        continue;
      }
      if (length <= 0) continue;
      // The face, offset by r towards the sphere.
      Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
      if (n.norm() < 1e-30) continue;
      n.normalize();
      if (n.dot(a - p0) < 0) n = -n;
      const double approach = n.dot(d);
      if (approach < 0) {
        const double t = (r - n.dot(a - p0)) / approach;
        if (t >= 0 && t <= length) {
          const Eigen::Vector3d touch = a + t * d - r * n;
          if ((closest_on_triangle(touch, p0, p1, p2) - touch).squaredNorm() < 1e-20) {
            consider(t, touch);
            continue;  // a face contact comes before any edge contact of this triangle
          }
        }
      }
      // Edges and corners.
      const Eigen::Vector3d* corners[3] = {&p0, &p1, &p2};
      for (int e = 0; e < 3; ++e) {
        const double t = enter_capsule(a, d, length, *corners[e], *corners[(e + 1) % 3], r);
        if (std::isfinite(t) && t < best_t) {
          consider(t, closest_on_triangle(a + t * d, p0, p1, p2));
        }
      }
    }
  }
}

MeshHit MeshCollider::sweep(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) const {
  MeshHit best;
  const Eigen::Vector3d delta = b - a;
  const double length = delta.norm();
  const Eigen::Vector3d d = length > 0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::Zero();
  double best_t = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_normal = Eigen::Vector3d::Zero();
  for (const Part& part : parts_) {
    if (!part.plane) {
      // Skip parts whose bounding sphere is out of reach of the swept sphere.
      const Eigen::Vector3d c = part.pose * part.centre;
      const double s = std::clamp((c - a).dot(d), 0.0, length);
      if ((a + s * d - c).norm() > part.bound + r) continue;
    }
    double t = best_t;
    Eigen::Vector3d point;
    const Eigen::Vector3d local_a = part.inverse * a;
    const Eigen::Vector3d local_d = part.inverse.linear() * d;
    sweep_part(part, local_a, local_d, length, r, t, point);
    if (t < best_t) {
      best_t = t;
      const Eigen::Vector3d away = local_a + t * local_d - point;
      best_normal = part.pose.linear() * (away.norm() > 0 ? Eigen::Vector3d(away.normalized())
                                                          : Eigen::Vector3d(-local_d));
    }
  }
  if (std::isfinite(best_t)) {
    best.hit = true;
    best.t = length > 0 ? best_t / length : 0.0;
    best.normal = best_normal;
  }
  return best;
}

}  // namespace ambfplus
