// SoftBodySpec: its checks and its keyword options (AMBF's `config` keys among them).

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/soft_body.h"
#include "scene/shared_options.h"

namespace ambfplus {
namespace {

// Throws unless lo <= value <= hi (and finite).
void require_range(double value, double lo, double hi, const std::string& who, const char* key) {
  if (!(value >= lo && value <= hi)) {
    throw ArgumentError(who + ": " + key + " must be in " + std::to_string(lo) + ".." +
                        std::to_string(hi) + ", got " + std::to_string(value));
  }
}

void require_at_least(double value, double lo, const std::string& who, const char* key) {
  if (!(value >= lo) || !std::isfinite(value)) {
    throw ArgumentError(who + ": " + key + " must be >= " + std::to_string(lo) + ", got " +
                        std::to_string(value));
  }
}

using C = SoftBodyConfig;
using V = const OptionValue&;
using K = const std::string&;
using O = OptionTable<C>::Option;

// A real coefficient of the config.
O real(const char* key, double C::*field, const char* help) {
  return O{key, "float", help, [field](C& c, V v, K k) { c.*field = v.number(k); }};
}

// A whole-number coefficient of the config.
O whole(const char* key, int C::*field, const char* help) {
  return O{key, "int", help, [field](C& c, V v, K k) { c.*field = v.integer(k); }};
}

}  // namespace

void SoftBodyConfig::validate(const std::string& who) const {
  require_range(linear_stiffness, 0, 1, who, "kLST (linear stiffness)");
  require_range(area_stiffness, 0, 1, who, "kAST (area stiffness)");
  require_range(volume_stiffness, 0, 1, who, "kVST (volume stiffness)");
  require_at_least(velocity_correction, 0, who, "kVCF (velocity correction)");
  require_range(damping, 0, 1, who, "kDP (damping)");
  require_at_least(drag, 0, who, "kDG (drag)");
  require_at_least(lift, 0, who, "kLF (lift)");
  if (!std::isfinite(pressure)) throw ArgumentError(who + ": kPR (pressure) must be finite");
  require_at_least(volume_conservation, 0, who, "kVC (volume conservation)");
  require_range(dynamic_friction, 0, 1, who, "kDF (dynamic friction)");
  if (pose_matching) require_range(*pose_matching, 0, 1, who, "kMT (pose matching)");
  require_range(rigid_hardness, 0, 1, who, "kCHR (rigid contact hardness)");
  require_range(kinetic_hardness, 0, 1, who, "kKHR (kinetic contact hardness)");
  require_range(soft_hardness, 0, 1, who, "kSHR (soft contact hardness)");
  require_range(anchor_hardness, 0, 1, who, "kAHR (anchor hardness)");
  require_range(cluster_rigid_hardness, 0, 1, who, "kSRHR_CL");
  require_range(cluster_kinetic_hardness, 0, 1, who, "kSKHR_CL");
  require_range(cluster_soft_hardness, 0, 1, who, "kSSHR_CL");
  require_range(cluster_rigid_impulse_split, 0, 1, who, "kSR_SPLT_CL");
  require_range(cluster_kinetic_impulse_split, 0, 1, who, "kSK_SPLT_CL");
  require_range(cluster_soft_impulse_split, 0, 1, who, "kSS_SPLT_CL");
  require_at_least(max_volume, 0, who, "maxvolume");
  if (!(time_scale > 0) || !std::isfinite(time_scale)) {
    throw ArgumentError(who + ": timescale must be > 0");
  }
  require_at_least(velocity_iterations, 0, who, "viterations");
  require_at_least(position_iterations, 0, who, "piterations");
  require_at_least(drift_iterations, 0, who, "diterations");
  require_at_least(cluster_iterations, 0, who, "citerations");
  require_at_least(collision_flags, 0, who, "flags");
  if (bending_constraint && *bending_constraint < 2) {
    throw ArgumentError(who + ": bending constraint is a distance in links and must be >= 2, got " +
                        std::to_string(*bending_constraint));
  }
  if (clusters) require_at_least(*clusters, 0, who, "clusters");
  for (int n : fixed_nodes) {
    if (n < 0) throw ArgumentError(who + ": fixed node " + std::to_string(n) + " is not a node");
  }
}

const OptionTable<SoftBodyConfig>& soft_body_config_options() {
  static const OptionTable<C> table(
      "soft body config",
      {
          real("kLST", &C::linear_stiffness, "linear stiffness, 0..1"),
          real("kAST", &C::area_stiffness, "area stiffness, 0..1"),
          real("kVST", &C::volume_stiffness, "volume stiffness, 0..1"),
          real("kVCF", &C::velocity_correction, "velocity correction factor"),
          real("kDP", &C::damping, "damping, 0..1"),
          real("kDG", &C::drag, "drag"),
          real("kLF", &C::lift, "lift"),
          real("kPR", &C::pressure, "pressure"),
          real("kVC", &C::volume_conservation, "volume conservation"),
          real("kDF", &C::dynamic_friction, "dynamic friction, 0..1"),
          O{"kMT", "float", "pose matching, 0..1",
            [](C& c, V v, K k) { c.pose_matching = v.number(k); }},
          real("kCHR", &C::rigid_hardness, "rigid contact hardness, 0..1"),
          real("kKHR", &C::kinetic_hardness, "kinetic contact hardness, 0..1"),
          real("kSHR", &C::soft_hardness, "soft contact hardness, 0..1"),
          real("kAHR", &C::anchor_hardness, "anchor hardness, 0..1"),
          real("kSRHR_CL", &C::cluster_rigid_hardness, "cluster-rigid hardness, 0..1"),
          real("kSKHR_CL", &C::cluster_kinetic_hardness, "cluster-kinetic hardness, 0..1"),
          real("kSSHR_CL", &C::cluster_soft_hardness, "cluster-soft hardness, 0..1"),
          real("kSR_SPLT_CL", &C::cluster_rigid_impulse_split, "0..1"),
          real("kSK_SPLT_CL", &C::cluster_kinetic_impulse_split, "0..1"),
          real("kSS_SPLT_CL", &C::cluster_soft_impulse_split, "0..1"),
          real("maxvolume", &C::max_volume, "largest volume ratio for pose"),
          real("timescale", &C::time_scale, "factor on the step"),
          whole("viterations", &C::velocity_iterations, "velocity solver passes"),
          whole("piterations", &C::position_iterations, "position solver passes"),
          whole("diterations", &C::drift_iterations, "drift solver passes"),
          whole("citerations", &C::cluster_iterations, "cluster solver passes"),
          whole("flags", &C::collision_flags, "Bullet's collision flags"),
          O{"bending_constraint", "int", "links apart that resist bending, >= 2",
            [](C& c, V v, K k) { c.bending_constraint = v.integer(k); }},
          O{"clusters", "int", "clusters (0: one per face)",
            [](C& c, V v, K k) { c.clusters = v.integer(k); }},
          O{"fixed_nodes", "list[int]", "nodes pinned where they are",
            [](C& c, V v, K k) { c.fixed_nodes = v.integers(k); }},
      });
  return table;
}

bool set_soft_body_config(SoftBodyConfig& config, const std::string& key, double value) {
  const auto* option = soft_body_config_options().find(key);
  if (option == nullptr || option->key == "fixed_nodes") return false;
  option->set(config, OptionValue(value), key);
  return true;
}

void SoftBodySpec::validate() const {
  const std::string who = "soft body '" + name + "'";
  if (mesh.empty()) throw ArgumentError(who + " needs a mesh file (STL, OBJ, ...)");
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw ArgumentError(who + ": scale must be > 0, got " + std::to_string(scale));
  }
  if (!(mass > 0) || !std::isfinite(mass)) {
    throw ArgumentError(who + ": mass must be > 0 kg, got " + std::to_string(mass));
  }
  require_at_least(margin, 0, who, "collision margin");
  config.validate(who);
  checked_pose(pose, who);
}

const OptionTable<SoftBodySpec>& soft_body_options() {
  using S = SoftBodySpec;
  using SO = OptionTable<S>::Option;
  static const OptionTable<S> table(
      "add_soft_body()",
      joined<SO>(
          {
              SO{"scale", "float", "of the mesh's vertices",
                 [](S& s, V v, K k) { s.scale = v.number(k); }},
              SO{"pose", "numpy.ndarray", "4x4 world from the mesh frame",
                 [](S& s, V v, K k) { s.pose = v.matrix4(k); }},
              SO{"mass", "float", "kg, shared evenly by the nodes",
                 [](S& s, V v, K k) { s.mass = v.number(k); }},
              SO{"margin", "float", "collision margin, m",
                 [](S& s, V v, K k) { s.margin = v.number(k); }},
              SO{"config", "dict[str, Any] | None", "AMBF's config block (kLST, ... fixed nodes)",
                 [](S& s, V v, K k) { soft_body_config_options().apply(s.config, v.map(k)); }},
              SO{"fixed_nodes", "list[int]", "nodes pinned where they are",
                 [](S& s, V v, K k) { s.config.fixed_nodes = v.integers(k); }},
              SO{"randomize_constraints", "bool", "shuffle the order the solver takes the links in",
                 [](S& s, V v, K k) { s.randomize_constraints = v.boolean(k); }},
          },
          material_options(&S::material)));
  return table;
}

}  // namespace ambfplus
