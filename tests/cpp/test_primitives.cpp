#include <gtest/gtest.h>

#include <cmath>

#include "scene/primitive_meshes.h"

namespace ambfplus {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d vertex(const MeshData& m, std::uint32_t i) {
  return {m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]};
}

// Signed volume by the divergence theorem: positive only if every face winds counter-clockwise
// seen from outside.
double signed_volume(const MeshData& m) {
  double v = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto a = vertex(m, m.indices[3 * t]), b = vertex(m, m.indices[3 * t + 1]),
               c = vertex(m, m.indices[3 * t + 2]);
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

// Every vertex normal agrees with the winding of the faces that use it.
void expect_normals_agree_with_winding(const MeshData& m) {
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t i[3] = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    const Eigen::Vector3d face =
        (vertex(m, i[1]) - vertex(m, i[0])).cross(vertex(m, i[2]) - vertex(m, i[0]));
    if (face.norm() < 1e-12) continue;  // degenerate slivers at poles carry no orientation
    for (std::uint32_t k : i) {
      const Eigen::Vector3d n(m.normals[3 * k], m.normals[3 * k + 1], m.normals[3 * k + 2]);
      ASSERT_GT(n.dot(face.normalized()), 0.0) << "triangle " << t;
    }
  }
}

Shape shape(Shape::Kind kind, double radius, double height) {
  Shape s;
  s.kind = kind;
  s.radius = radius;
  s.height = height;
  return s;
}

TEST(Primitives, BoxIsClosedOutwardAndExact) {
  Shape s;
  s.kind = Shape::Kind::kBox;
  s.size = {0.2, 0.4, 0.8};
  const MeshData m = make_primitive_mesh(s);
  EXPECT_NEAR(signed_volume(m) / (0.2 * 0.4 * 0.8), 1.0, 1e-6);  // float vertices
  expect_normals_agree_with_winding(m);
}

TEST(Primitives, RoundShapesHaveTheirVolume) {
  const double r = 0.3, h = 1.0;
  // Inscribed polygons lose a little volume: 64 segments keep it within 0.5 %.
  struct Case {
    Shape::Kind kind;
    double volume;
  } cases[] = {
      {Shape::Kind::kSphere, 4.0 / 3.0 * kPi * r * r * r},
      {Shape::Kind::kCylinder, kPi * r * r * h},
      {Shape::Kind::kCapsule, kPi * r * r * (h - 2 * r) + 4.0 / 3.0 * kPi * r * r * r},
      {Shape::Kind::kCone, kPi * r * r * h / 3.0},
  };
  for (const Case& c : cases) {
    const MeshData m = make_primitive_mesh(shape(c.kind, r, h));
    EXPECT_NEAR(signed_volume(m) / c.volume, 1.0, 5e-3) << shape_kind_name(c.kind);
    expect_normals_agree_with_winding(m);
  }
}

TEST(Primitives, CapsuleHeightIncludesCaps) {
  const MeshData m = make_primitive_mesh(shape(Shape::Kind::kCapsule, 0.1, 0.5));
  double zmin = 1e9, zmax = -1e9;
  for (std::size_t i = 0; i < m.vertex_count(); ++i) {
    zmin = std::min<double>(zmin, m.positions[3 * i + 2]);
    zmax = std::max<double>(zmax, m.positions[3 * i + 2]);
  }
  EXPECT_NEAR(zmin, -0.25, 1e-6);
  EXPECT_NEAR(zmax, 0.25, 1e-6);
}

TEST(Primitives, PlaneIsAFanToInfinity) {
  const MeshData m = make_primitive_mesh(shape(Shape::Kind::kPlane, 0, 0));
  ASSERT_EQ(m.position_size, 4);
  EXPECT_EQ(m.triangle_count(), 4u);
  EXPECT_EQ(m.positions[3], 1.0f);  // the origin is finite
  for (std::size_t v = 1; v < m.vertex_count(); ++v) EXPECT_EQ(m.positions[4 * v + 3], 0.0f);
}

}  // namespace
}  // namespace ambfplus
