// Iso-surface extraction by surface nets: one vertex per grid cell the surface crosses (the mean
// of its edge crossings), one quad per crossed grid edge joining the four cells around it.

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unordered_map>

#include <Eigen/Geometry>

#include "ambfplus/errors.h"
#include "ambfplus/io/mesh.h"
#include "ambfplus/volume/volume_io.h"
#include "util/strings.h"
#include "volume/grid_access.h"

namespace ambfplus {
namespace {

// Cells sit between voxel centres: cell (i, j, k) has corner voxels (i..i+1, j..j+1, k..k+1) and
// runs from -1 to n-1 along each axis, so surfaces touching the grid's edge still close.
MeshData surface_nets(const VolumeField& f, double level) {
  const auto& n = f.shape;
  auto cell_key = [&](int i, int j, int k) {
    return (std::int64_t(i + 1) * (n[1] + 1) + (j + 1)) * (n[2] + 1) + (k + 1);
  };
  MeshData mesh;
  std::unordered_map<std::int64_t, std::uint32_t> vertex_of;
  static const int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                    {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  auto vertex = [&](int i, int j, int k) -> std::uint32_t {
    const std::int64_t key = cell_key(i, j, k);
    auto it = vertex_of.find(key);
    if (it != vertex_of.end()) return it->second;
    double v[8];
    Eigen::Vector3d corner[8];
    for (int c = 0; c < 8; ++c) {
      const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
      v[c] = f.at(i + di, j + dj, k + dk);
      corner[c] = Eigen::Vector3d(i + di + 0.5, j + dj + 0.5, k + dk + 0.5);
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int crossings = 0;
    for (const auto& e : kEdges) {
      const double a = v[e[0]], b = v[e[1]];
      if ((a >= level) == (b >= level)) continue;
      const double t = (level - a) / (b - a);
      sum += corner[e[0]] + t * (corner[e[1]] - corner[e[0]]);
      ++crossings;
    }
    const Eigen::Vector3d p = sum / std::max(crossings, 1);
    const Eigen::Vector3d g = f.gradient(p);
    const Eigen::Vector3d normal =
        g.norm() > 0 ? Eigen::Vector3d(-g.normalized()) : Eigen::Vector3d::UnitZ();
    const auto index = static_cast<std::uint32_t>(mesh.positions.size() / 3);
    mesh.positions.insert(mesh.positions.end(), {float(p.x()), float(p.y()), float(p.z())});
    mesh.normals.insert(mesh.normals.end(),
                        {float(normal.x()), float(normal.y()), float(normal.z())});
    vertex_of.emplace(key, index);
    return index;
  };
  auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
  };
  // Every grid edge between voxel centres p and p + e_axis with a crossing gives a quad.
  for (int k = -1; k < n[2]; ++k) {
    for (int j = -1; j < n[1]; ++j) {
      for (int i = -1; i < n[0]; ++i) {
        const bool inside = f.at(i, j, k) >= level;
        for (int axis = 0; axis < 3; ++axis) {
          const int ni = i + (axis == 0), nj = j + (axis == 1), nk = k + (axis == 2);
          if (ni >= n[0] || nj >= n[1] || nk >= n[2]) continue;
          if (inside == (f.at(ni, nj, nk) >= level)) continue;
          // The four cells around the edge, counter-clockwise seen from the edge's +axis end.
          std::uint32_t c[4];
          if (axis == 0) {
            c[0] = vertex(i, j - 1, k - 1), c[1] = vertex(i, j, k - 1), c[2] = vertex(i, j, k),
            c[3] = vertex(i, j - 1, k);
          } else if (axis == 1) {
            c[0] = vertex(i - 1, j, k - 1), c[1] = vertex(i - 1, j, k), c[2] = vertex(i, j, k),
            c[3] = vertex(i, j, k - 1);
          } else {
            c[0] = vertex(i - 1, j - 1, k), c[1] = vertex(i, j - 1, k), c[2] = vertex(i, j, k),
            c[3] = vertex(i - 1, j, k);
          }
          // Outward is from solid to empty: along +axis when the solid side is this end.
          if (inside) {
            quad(c[0], c[1], c[2], c[3]);
          } else {
            quad(c[0], c[3], c[2], c[1]);
          }
        }
      }
    }
  }
  return mesh;
}

void write_stl(const std::string& path, const MeshData& m) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "ambfplus surface mesh", sizeof(header));
  out.write(header, 80);
  const auto count = static_cast<std::uint32_t>(m.triangle_count());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    Eigen::Vector3f v[3];
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t i = m.indices[3 * t + c];
      v[c] = Eigen::Vector3f(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]);
    }
    Eigen::Vector3f n = (v[1] - v[0]).cross(v[2] - v[0]);
    if (n.norm() > 0) n.normalize();
    out.write(reinterpret_cast<const char*>(n.data()), 12);
    for (const auto& p : v) out.write(reinterpret_cast<const char*>(p.data()), 12);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
  if (!out)
    throw ConfigError(path, std::string("cannot write the STL file: ") + std::strerror(errno));
}

void write_ply(const std::string& path, const MeshData& m) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\ncomment ambfplus surface mesh, metres\n"
      << "element vertex " << m.vertex_count() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\n"
      << "element face " << m.triangle_count() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    out.write(reinterpret_cast<const char*>(&m.positions[3 * v]), 12);
    out.write(reinterpret_cast<const char*>(&m.normals[3 * v]), 12);
  }
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint8_t three = 3;
    out.write(reinterpret_cast<const char*>(&three), 1);
    for (int c = 0; c < 3; ++c) {
      const auto i = static_cast<std::int32_t>(m.indices[3 * t + c]);
      out.write(reinterpret_cast<const char*>(&i), 4);
    }
  }
  if (!out)
    throw ConfigError(path, std::string("cannot write the PLY file: ") + std::strerror(errno));
}

}  // namespace

std::int64_t write_surface_mesh(VolumeData& volume, const std::string& path, std::uint16_t label,
                                double iso) {
  const std::string ext = to_lower(std::filesystem::path(path).extension().string());
  if (ext != ".stl" && ext != ".ply") {
    throw ConfigError(path, "a surface mesh is written as .stl or .ply, not '" + ext + "'");
  }
  // One label: mesh a grid that holds only that label.
  std::shared_ptr<VolumeData> only;
  VolumeData* source = &volume;
  if (label != 0) {
    if (!volume.label_table().find(label)) {
      throw ArgumentError("label " + std::to_string(label) + " is not in the volume's table");
    }
    only = std::make_shared<VolumeData>(volume.shape(), volume.dimensions(), LabelType::kUInt8,
                                        LabelTable());
    auto* mask = static_cast<std::uint8_t*>(only->label_data());
    visit_labels(volume.label_type(), volume.label_data(), [&](const auto* labels) {
      for (std::int64_t v = 0; v < volume.voxel_count(); ++v) mask[v] = labels[v] == label;
    });
    source = only.get();
  }
  const VolumeField field{source->smoothed_occupancy().data(), source->shape()};
  MeshData mesh = surface_nets(field, iso * 255.0);
  // Voxel units to the volume frame, metres.
  const Eigen::Vector3d s = volume.voxel_size(), half = volume.dimensions() / 2;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int a = 0; a < 3; ++a) {
      mesh.positions[3 * v + a] = static_cast<float>(mesh.positions[3 * v + a] * s[a] - half[a]);
    }
    Eigen::Vector3d n(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]);
    n = n.cwiseQuotient(s).normalized();
    for (int a = 0; a < 3; ++a) mesh.normals[3 * v + a] = static_cast<float>(n[a]);
  }
  if (ext == ".stl") {
    write_stl(path, mesh);
  } else {
    write_ply(path, mesh);
  }
  return static_cast<std::int64_t>(mesh.triangle_count());
}

}  // namespace ambfplus
