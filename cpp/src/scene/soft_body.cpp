// SoftBody's scene side: checking the spec and turning the mesh into nodes and triangles.

#include "ambfplus/scene/soft_body.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include "ambfplus/errors.h"
#include "ambfplus/io/mesh.h"

namespace ambfplus {
namespace {

// Positions as a hashable key (bit patterns, with -0 folded onto +0).
struct PositionKey {
  float p[3];
  bool operator==(const PositionKey& o) const { return std::memcmp(p, o.p, sizeof(p)) == 0; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint32_t bits[3];
    std::memcpy(bits, k.p, sizeof(bits));
    std::size_t h = 1469598103934665603ull;
    for (std::uint32_t b : bits) h = (h ^ b) * 1099511628211ull;
    return h;
  }
};

}  // namespace

SoftBody::SoftBody(Model& model, const SoftBodySpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string& name = spec.name;
  spec.validate();
  const Eigen::Isometry3d pose = checked_pose(spec_.pose);

  const MeshData mesh = load_mesh(spec_.mesh, spec_.scale);
  // One node per distinct position (files such as STL repeat a vertex for every face), in the
  // order the mesh first uses them, placed in the world.
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> nodes;
  std::vector<std::uint32_t> node_of(mesh.vertex_count());
  const int stride = mesh.position_size;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    PositionKey key{};
    for (int a = 0; a < 3; ++a) key.p[a] = mesh.positions[v * stride + a] + 0.0f;  // -0 -> +0
    const auto [it, added] = nodes.emplace(key, static_cast<std::uint32_t>(nodes.size()));
    node_of[v] = it->second;
    if (added) {
      const Eigen::Vector3d p = pose * Eigen::Vector3d(key.p[0], key.p[1], key.p[2]);
      positions_.insert(positions_.end(), {p.x(), p.y(), p.z()});
    }
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t a = node_of[mesh.indices[3 * t]], b = node_of[mesh.indices[3 * t + 1]],
                        c = node_of[mesh.indices[3 * t + 2]];
    if (a == b || b == c || c == a) continue;  // collapsed by the merge
    triangles_.insert(triangles_.end(), {a, b, c});
  }
  if (triangles_.empty()) {
    throw ConfigError(spec_.mesh, "soft body '" + name + "': the mesh has no triangles");
  }
  if (!(Eigen::Map<const Eigen::VectorXd>(positions_.data(), positions_.size()).allFinite())) {
    throw ConfigError(spec_.mesh, "soft body '" + name + "': the mesh has non-finite vertices");
  }
  const int count = static_cast<int>(node_count());
  for (int n : spec_.config.fixed_nodes) {
    if (n < 0 || n >= count) {
      throw ArgumentError("soft body '" + name + "': fixed node " + std::to_string(n) +
                          " is not a node; the mesh gives " + std::to_string(count) + " (0.." +
                          std::to_string(count - 1) + ")");
    }
  }
  Eigen::Isometry3d start = pose;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int n = 0; n < count; ++n) centroid += node_position(n);
  start.translation() = centroid / count;
  Object::set_pose(start);
}

Eigen::Vector3d SoftBody::node_position(int node) const {
  check_node(node);
  const double* p = positions_.data() + 3 * node;
  return Eigen::Vector3d(p[0], p[1], p[2]);
}

void SoftBody::check_node(int node) const {
  if (node < 0 || node >= static_cast<int>(node_count())) {
    throw OutOfRange("soft body '" + name() + "' has nodes 0.." +
                     std::to_string(static_cast<int>(node_count()) - 1) + ", not " +
                     std::to_string(node));
  }
}

SoftBody::~SoftBody() = default;

}  // namespace ambfplus
