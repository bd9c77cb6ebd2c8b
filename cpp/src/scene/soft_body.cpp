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

// Throws unless lo <= value <= hi (and finite).
void require_range(double value, double lo, double hi, const std::string& body, const char* key) {
  if (!(value >= lo && value <= hi)) {
    throw ArgumentError("soft body '" + body + "': " + key + " must be in " + std::to_string(lo) +
                        ".." + std::to_string(hi) + ", got " + std::to_string(value));
  }
}

void require_at_least(double value, double lo, const std::string& body, const char* key) {
  if (!(value >= lo) || !std::isfinite(value)) {
    throw ArgumentError("soft body '" + body + "': " + key + " must be >= " + std::to_string(lo) +
                        ", got " + std::to_string(value));
  }
}

void check_config(const SoftBodyConfig& c, const std::string& name) {
  require_range(c.linear_stiffness, 0, 1, name, "kLST (linear stiffness)");
  require_range(c.area_stiffness, 0, 1, name, "kAST (area stiffness)");
  require_range(c.volume_stiffness, 0, 1, name, "kVST (volume stiffness)");
  require_at_least(c.velocity_correction, 0, name, "kVCF (velocity correction)");
  require_range(c.damping, 0, 1, name, "kDP (damping)");
  require_at_least(c.drag, 0, name, "kDG (drag)");
  require_at_least(c.lift, 0, name, "kLF (lift)");
  if (!std::isfinite(c.pressure)) {
    throw ArgumentError("soft body '" + name + "': kPR (pressure) must be finite");
  }
  require_at_least(c.volume_conservation, 0, name, "kVC (volume conservation)");
  require_range(c.dynamic_friction, 0, 1, name, "kDF (dynamic friction)");
  if (c.pose_matching) require_range(*c.pose_matching, 0, 1, name, "kMT (pose matching)");
  require_range(c.rigid_hardness, 0, 1, name, "kCHR (rigid contact hardness)");
  require_range(c.kinetic_hardness, 0, 1, name, "kKHR (kinetic contact hardness)");
  require_range(c.soft_hardness, 0, 1, name, "kSHR (soft contact hardness)");
  require_range(c.anchor_hardness, 0, 1, name, "kAHR (anchor hardness)");
  require_range(c.cluster_rigid_hardness, 0, 1, name, "kSRHR_CL");
  require_range(c.cluster_kinetic_hardness, 0, 1, name, "kSKHR_CL");
  require_range(c.cluster_soft_hardness, 0, 1, name, "kSSHR_CL");
  require_range(c.cluster_rigid_impulse_split, 0, 1, name, "kSR_SPLT_CL");
  require_range(c.cluster_kinetic_impulse_split, 0, 1, name, "kSK_SPLT_CL");
  require_range(c.cluster_soft_impulse_split, 0, 1, name, "kSS_SPLT_CL");
  require_at_least(c.max_volume, 0, name, "maxvolume");
  if (!(c.time_scale > 0) || !std::isfinite(c.time_scale)) {
    throw ArgumentError("soft body '" + name + "': timescale must be > 0");
  }
  require_at_least(c.velocity_iterations, 0, name, "viterations");
  require_at_least(c.position_iterations, 0, name, "piterations");
  require_at_least(c.drift_iterations, 0, name, "diterations");
  require_at_least(c.cluster_iterations, 0, name, "citerations");
  require_at_least(c.collision_flags, 0, name, "flags");
  if (c.bending_constraint && *c.bending_constraint < 2) {
    throw ArgumentError("soft body '" + name +
                        "': bending constraint is a distance in links and must be >= 2, "
                        "got " +
                        std::to_string(*c.bending_constraint));
  }
  if (c.clusters) require_at_least(*c.clusters, 0, name, "clusters");
}

// An integer config value: throws unless `value` is a whole number.
int whole(double value, const std::string& key) {
  if (!std::isfinite(value) || std::floor(value) != value) {
    throw ArgumentError("soft body config key '" + key + "' takes a whole number, got " +
                        std::to_string(value));
  }
  return static_cast<int>(value);
}

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

bool set_soft_body_config(SoftBodyConfig& c, const std::string& key, double v) {
  std::string k = key;
  for (char& ch : k) {
    if (ch == '_' && k.rfind("k", 0) != 0) ch = ' ';  // "bending_constraint", not "kSR_SPLT_CL"
  }
  if (k == "kLST") {
    c.linear_stiffness = v;
  } else if (k == "kAST") {
    c.area_stiffness = v;
  } else if (k == "kVST") {
    c.volume_stiffness = v;
  } else if (k == "kVCF") {
    c.velocity_correction = v;
  } else if (k == "kDP") {
    c.damping = v;
  } else if (k == "kDG") {
    c.drag = v;
  } else if (k == "kLF") {
    c.lift = v;
  } else if (k == "kPR") {
    c.pressure = v;
  } else if (k == "kVC") {
    c.volume_conservation = v;
  } else if (k == "kDF") {
    c.dynamic_friction = v;
  } else if (k == "kMT") {
    c.pose_matching = v;
  } else if (k == "kCHR") {
    c.rigid_hardness = v;
  } else if (k == "kKHR") {
    c.kinetic_hardness = v;
  } else if (k == "kSHR") {
    c.soft_hardness = v;
  } else if (k == "kAHR") {
    c.anchor_hardness = v;
  } else if (k == "kSRHR_CL") {
    c.cluster_rigid_hardness = v;
  } else if (k == "kSKHR_CL") {
    c.cluster_kinetic_hardness = v;
  } else if (k == "kSSHR_CL") {
    c.cluster_soft_hardness = v;
  } else if (k == "kSR_SPLT_CL") {
    c.cluster_rigid_impulse_split = v;
  } else if (k == "kSK_SPLT_CL") {
    c.cluster_kinetic_impulse_split = v;
  } else if (k == "kSS_SPLT_CL") {
    c.cluster_soft_impulse_split = v;
  } else if (k == "maxvolume") {
    c.max_volume = v;
  } else if (k == "timescale") {
    c.time_scale = v;
  } else if (k == "viterations") {
    c.velocity_iterations = whole(v, key);
  } else if (k == "piterations") {
    c.position_iterations = whole(v, key);
  } else if (k == "diterations") {
    c.drift_iterations = whole(v, key);
  } else if (k == "citerations") {
    c.cluster_iterations = whole(v, key);
  } else if (k == "flags") {
    c.collision_flags = whole(v, key);
  } else if (k == "bending constraint") {
    c.bending_constraint = whole(v, key);
  } else if (k == "clusters") {
    c.clusters = whole(v, key);
  } else {
    return false;
  }
  return true;
}

SoftBody::SoftBody(Model& model, const SoftBodySpec& spec, int id)
    : Object(model, spec.name, id), spec_(spec) {
  const std::string& name = spec.name;
  if (spec_.mesh.empty()) {
    throw ArgumentError("soft body '" + name + "' needs a mesh file (STL, OBJ, ...)");
  }
  if (!(spec_.scale > 0) || !std::isfinite(spec_.scale)) {
    throw ArgumentError("soft body '" + name + "': scale must be > 0, got " +
                        std::to_string(spec_.scale));
  }
  if (!(spec_.mass > 0) || !std::isfinite(spec_.mass)) {
    throw ArgumentError("soft body '" + name + "': mass must be > 0 kg, got " +
                        std::to_string(spec_.mass));
  }
  require_at_least(spec_.margin, 0, name, "collision margin");
  check_config(spec_.config, name);
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
