#include "scene/primitive_meshes.h"

#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Core>

namespace ambfplus {
namespace {

constexpr int kSegments = 64;  // around the z axis
constexpr int kRings = 32;     // pole to pole on spheres and caps
constexpr double kPi = 3.14159265358979323846;

class MeshBuilder {
 public:
  std::uint32_t vertex(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    const Eigen::Vector3d u = n.normalized();
    for (int i = 0; i < 3; ++i) {
      mesh_.positions.push_back(static_cast<float>(p[i]));
      mesh_.normals.push_back(static_cast<float>(u[i]));
    }
    return static_cast<std::uint32_t>(mesh_.positions.size() / 3 - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    mesh_.indices.insert(mesh_.indices.end(), {a, b, c});
  }
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  // A flat disc at height z facing +z (up) or -z.
  void disc(double radius, double z, bool up) {
    const Eigen::Vector3d n(0, 0, up ? 1 : -1);
    const std::uint32_t centre = vertex({0, 0, z}, n);
    for (int i = 0; i <= kSegments; ++i) {
      const double a = 2 * kPi * i / kSegments;
      const std::uint32_t v = vertex({radius * std::cos(a), radius * std::sin(a), z}, n);
      if (i == 0) continue;
      if (up) {
        triangle(centre, v - 1, v);
      } else {
        triangle(centre, v, v - 1);
      }
    }
  }
  // A surface of revolution about z through (r, z) profile points, normals given per point.
  void revolve(const std::vector<Eigen::Vector2d>& profile,
               const std::vector<Eigen::Vector2d>& normals) {
    const std::uint32_t base = static_cast<std::uint32_t>(mesh_.positions.size() / 3);
    for (std::size_t k = 0; k < profile.size(); ++k) {
      for (int i = 0; i <= kSegments; ++i) {
        const double a = 2 * kPi * i / kSegments;
        const double c = std::cos(a), s = std::sin(a);
        vertex({profile[k].x() * c, profile[k].x() * s, profile[k].y()},
               {normals[k].x() * c, normals[k].x() * s, normals[k].y()});
      }
    }
    const std::uint32_t row = kSegments + 1;
    for (std::uint32_t k = 0; k + 1 < profile.size(); ++k) {
      for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(kSegments); ++i) {
        const std::uint32_t a = base + k * row + i;
        // Profiles run bottom to top, so (a, a+1, a+1+row) is counter-clockwise from outside.
        quad(a, a + 1, a + 1 + row, a + row);
      }
    }
  }
  MeshData take() { return std::move(mesh_); }

 private:
  MeshData mesh_;
};

MeshData box(const Eigen::Vector3d& size) {
  MeshBuilder b;
  const Eigen::Vector3d h = size / 2;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      const Eigen::Vector3d u = Eigen::Vector3d::Unit((axis + 1) % 3);
      const Eigen::Vector3d v = Eigen::Vector3d::Unit((axis + 2) % 3);
      // u x v = n for sign +1; swap the order for -1 to keep faces counter-clockwise outside.
      const Eigen::Vector3d c = n.cwiseProduct(h);
      const Eigen::Vector3d du = u.cwiseProduct(h), dv = v.cwiseProduct(h);
      const std::uint32_t p0 = b.vertex(c - du - dv, n), p1 = b.vertex(c + du - dv, n),
                          p2 = b.vertex(c + du + dv, n), p3 = b.vertex(c - du + dv, n);
      if (sign > 0) {
        b.quad(p0, p1, p2, p3);
      } else {
        b.quad(p0, p3, p2, p1);
      }
    }
  }
  return b.take();
}

// A sphere-like profile: a cap of radius r centred at height zc, from angle t0 to t1
// (angles from the -z pole: 0 bottom, pi top).
void cap_profile(double r, double zc, double t0, double t1, int rings,
                 std::vector<Eigen::Vector2d>& p, std::vector<Eigen::Vector2d>& n) {
  for (int k = 0; k <= rings; ++k) {
    const double t = t0 + (t1 - t0) * k / rings;
    const Eigen::Vector2d dir(std::sin(t), -std::cos(t));
    p.push_back({r * dir.x(), zc + r * dir.y()});
    n.push_back(dir);
  }
}

MeshData sphere(double r) {
  std::vector<Eigen::Vector2d> p, n;
  cap_profile(r, 0, 0, kPi, kRings, p, n);
  MeshBuilder b;
  b.revolve(p, n);
  return b.take();
}

MeshData cylinder(double r, double h) {
  MeshBuilder b;
  b.revolve({{r, -h / 2}, {r, h / 2}}, {{1, 0}, {1, 0}});
  b.disc(r, h / 2, true);
  b.disc(r, -h / 2, false);
  return b.take();
}

MeshData capsule(double r, double h) {
  const double half = h / 2 - r;  // the height includes both caps
  std::vector<Eigen::Vector2d> p, n;
  cap_profile(r, -half, 0, kPi / 2, kRings / 2, p, n);
  cap_profile(r, half, kPi / 2, kPi, kRings / 2, p, n);
  MeshBuilder b;
  b.revolve(p, n);
  return b.take();
}

MeshData cone(double r, double h) {
  // Apex at +h/2, base at -h/2; the side normal leans up by atan(r / h).
  const Eigen::Vector2d side = Eigen::Vector2d(h, r).normalized();
  MeshBuilder b;
  b.revolve({{r, -h / 2}, {0, h / 2}}, {side, side});
  b.disc(r, -h / 2, false);
  return b.take();
}

MeshData plane() {
  MeshData m;
  m.position_size = 4;
  // The origin, then directions to infinity along +x, +y, -x, -y.
  m.positions = {0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, -1, 0, 0};
  for (int i = 0; i < 5; ++i) m.normals.insert(m.normals.end(), {0, 0, 1});
  m.indices = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1};
  return m;
}

// Turns a mesh built along z onto axis 0 (x) or 1 (y): a cyclic permutation of the coordinates,
// which is a rotation.
MeshData along_axis(MeshData m, int axis) {
  if (axis == 2) return m;
  const int shift = axis == 0 ? 1 : 2;  // z -> x: (x, y, z) -> (z, x, y)
  auto turn = [&](std::vector<float>& v, int stride) {
    for (std::size_t i = 0; i + 2 < v.size(); i += stride) {
      const float p[3] = {v[i], v[i + 1], v[i + 2]};
      for (int a = 0; a < 3; ++a) v[i + a] = p[(a + 3 - shift) % 3];
    }
  };
  turn(m.positions, m.position_size);
  turn(m.normals, 3);
  return m;
}

}  // namespace

MeshData make_primitive_mesh(const Shape& shape) {
  if (shape.axis < 0 || shape.axis > 2) {
    throw ArgumentError("shape axis must be 0 (x), 1 (y) or 2 (z)");
  }
  switch (shape.kind) {
    case Shape::Kind::kBox:
      return box(shape.size);
    case Shape::Kind::kSphere:
      return sphere(shape.radius);
    case Shape::Kind::kCylinder:
      return along_axis(cylinder(shape.radius, shape.height), shape.axis);
    case Shape::Kind::kCapsule:
      return along_axis(capsule(shape.radius, shape.height), shape.axis);
    case Shape::Kind::kCone:
      return along_axis(cone(shape.radius, shape.height), shape.axis);
    case Shape::Kind::kPlane:
      return plane();
    case Shape::Kind::kNone:
      return MeshData{};
    case Shape::Kind::kMesh:
      break;
  }
  throw ArgumentError("make_primitive_mesh: a mesh shape is not a primitive");
}

}  // namespace ambfplus
