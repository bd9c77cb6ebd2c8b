#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/rigid_body.h"

namespace ambfplus {

/// Bullet's soft-body coefficients, one field per key of an AMBF soft body's `config` block, with
/// AMBF's defaults. Ranges are Bullet's.
struct AMBFPLUS_API SoftBodyConfig {
  double linear_stiffness = 1.0;     ///< `kLST`: stiffness of the links (edges), 0..1; AMBF 1
  double area_stiffness = 1.0;       ///< `kAST`: area/angular stiffness, 0..1; AMBF 1
  double volume_stiffness = 1.0;     ///< `kVST`: volume stiffness, 0..1; AMBF 1
  double velocity_correction = 1.0;  ///< `kVCF`: velocity correction factor (Baumgarte); AMBF 1
  /// `kDP`: share of the node velocities taken away every step (a drag that depends on the step),
  /// 0..1; AMBF 0.
  double damping = 0.0;
  double drag = 0.0;      ///< `kDG`: aerodynamic drag, >= 0; AMBF 0
  double lift = 0.0;      ///< `kLF`: aerodynamic lift, >= 0; AMBF 0
  double pressure = 0.0;  ///< `kPR`: pressure (closed meshes); AMBF 0
  /// `kVC`: volume conservation, >= 0; AMBF 0. When > 0 the rest volume is recorded, which AMBF
  /// does not do (there kVC pulls a closed mesh towards zero volume).
  double volume_conservation = 0.0;
  double dynamic_friction = 0.2;  ///< `kDF`: friction against other bodies, 0..1; AMBF 0.2
  /// `kMT`: pose matching, 0..1: the pull back towards the rest shape. AMBF applies it (and records
  /// the rest shape) only when the key is given; absent here means the same.
  std::optional<double> pose_matching;
  double rigid_hardness = 1.0;                 ///< `kCHR`: rigid contact hardness, 0..1; AMBF 1
  double kinetic_hardness = 0.1;               ///< `kKHR`: kinetic contact hardness, 0..1; AMBF 0.1
  double soft_hardness = 1.0;                  ///< `kSHR`: soft contact hardness, 0..1; AMBF 1
  double anchor_hardness = 0.7;                ///< `kAHR`: anchor hardness, 0..1; AMBF 0.7
  double cluster_rigid_hardness = 0.1;         ///< `kSRHR_CL`: cluster-rigid hardness; AMBF 0.1
  double cluster_kinetic_hardness = 1.0;       ///< `kSKHR_CL`: cluster-kinetic hardness; AMBF 1
  double cluster_soft_hardness = 0.5;          ///< `kSSHR_CL`: cluster-soft hardness; AMBF 0.5
  double cluster_rigid_impulse_split = 0.5;    ///< `kSR_SPLT_CL`, 0..1; AMBF 0.5
  double cluster_kinetic_impulse_split = 0.5;  ///< `kSK_SPLT_CL`, 0..1; AMBF 0.5
  double cluster_soft_impulse_split = 0.5;     ///< `kSS_SPLT_CL`, 0..1; AMBF 0.5
  double max_volume = 1.0;      ///< `maxvolume`: largest volume ratio for pose; AMBF 1
  double time_scale = 1.0;      ///< `timescale`: factor on the step; AMBF 1
  int velocity_iterations = 0;  ///< `viterations`: velocity solver passes; AMBF 0
  int position_iterations = 1;  ///< `piterations`: position solver passes; AMBF 1
  int drift_iterations = 0;     ///< `diterations`: drift solver passes; AMBF 0
  int cluster_iterations = 4;   ///< `citerations`: cluster solver passes; AMBF 4
  /// `flags`: Bullet's collision flags (fCollision): 0x1 SDF_RS (nodes against rigid bodies by
  /// signed distance), 0x2 CL_RS (clusters against rigid bodies), 0x10 VF_SS, 0x20 CL_SS,
  /// 0x40 CL_SELF; AMBF 0x1.
  int collision_flags = 0x1;
  /// `bending constraint`: links between nodes this many links apart (2 or more) resist bending;
  /// absent: none (AMBF).
  std::optional<int> bending_constraint;
  /// `clusters`: groups the nodes into this many clusters (0: one per face); absent: none (AMBF).
  std::optional<int> clusters;
  /// `fixed nodes`: nodes pinned where they are (indices into SoftBody::node_positions, i.e. the
  /// mesh's vertices in order with duplicate positions merged). AMBF 2.0's loader pins nodes
  /// 0..k-1 for a list of k entries (their positions in the list, not their values); the values
  /// are what a file means.
  std::vector<int> fixed_nodes;

  /// Throws ArgumentError naming `who` and the key unless every coefficient is in its range.
  void validate(const std::string& who) const;
};

/// The keys of an AMBF soft body's `config` block, Python's and the file's alike: kLST ...
/// kSS_SPLT_CL, maxvolume, timescale, viterations, piterations, diterations, citerations, flags,
/// `bending constraint`, clusters, `fixed nodes` (spaces or underscores).
AMBFPLUS_API const OptionTable<SoftBodyConfig>& soft_body_config_options();

/// Sets the numeric SoftBodyConfig field an AMBF `config` key names (as
/// soft_body_config_options()). Returns false for a key it does not know (and for `fixed
/// nodes`, a list); throws ArgumentError for an integer key given a fraction.
AMBFPLUS_API bool set_soft_body_config(SoftBodyConfig& config, const std::string& key,
                                       double value);

/// Everything needed to create a soft body: AMBF's `soft bodies` block.
struct AMBFPLUS_API SoftBodySpec {
  std::string name;  ///< `name`
  /// `mesh` (resolved against the model's paths): its vertices (duplicates merged) become the
  /// nodes, its triangle edges the links. AMBF builds the body from the collision mesh (`collision
  /// mesh`, else `mesh`, under `low resolution path`) and draws it with the same vertices.
  std::string mesh;
  double scale = 1.0;  ///< `scale`, applied to the mesh's vertices; AMBF 1
  /// `location` {position, orientation}: world from the mesh frame when created.
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  double mass = 1.0;      ///< `mass`, kg, shared evenly by the nodes (as AMBF does); AMBF 1
  double margin = 0.001;  ///< `collision margin`, m: contact distance of the nodes; AMBF 0.001
  SoftBodyConfig config;  ///< `config`
  /// `randomize constraints`: shuffle the order the solver takes the links in. (AMBF 2.0 turns it
  /// on whenever the key is present, even as false.)
  bool randomize_constraints = false;
  Material material;  ///< `color` / `color rgba` / `color components`

  /// Throws ArgumentError naming the soft body and the key unless every value can be used (the
  /// fixed nodes are checked against the mesh when it is read).
  void validate() const;
};

/// add_soft_body's keyword options: scale, pose, mass, margin, config (a dict of the `config`
/// keys), fixed_nodes, randomize_constraints, color, specular, shininess, visible.
AMBFPLUS_API const OptionTable<SoftBodySpec>& soft_body_options();

namespace physics {
class PhysicsWorld;
}  // namespace physics

/// A deformable body simulated by Bullet: nodes at the mesh's vertices joined by links along its
/// triangle edges, colliding with rigid bodies. Its pose is the nodes' centroid with the
/// orientation it was created (or last posed) with.
class AMBFPLUS_API SoftBody : public Object {
 public:
  ~SoftBody() override;
  ObjectKind kind() const override { return ObjectKind::kSoftBody; }
  const SoftBodySpec& spec() const { return spec_; }
  double mass() const { return spec_.mass; }
  const Material& material() const { return spec_.material; }
  void set_material(const Material& material) { spec_.material = material; }

  std::size_t node_count() const { return positions_.size() / 3; }
  /// Node positions, world frame, x y z per node (refreshed by every world step and every change).
  const std::vector<double>& node_positions() const { return positions_; }
  Eigen::Vector3d node_position(int node) const;
  /// Node velocities, world frame, x y z per node (m/s).
  std::vector<double> node_velocities() const;
  /// Three node indices per triangle (the mesh's faces).
  const std::vector<std::uint32_t>& triangles() const { return triangles_; }

  /// Moves a node there at once (its velocity is kept).
  void set_node_position(int node, const Eigen::Vector3d& position);
  /// Pins a node where it is (fixed: physics does not move it) or frees it again.
  void set_node_fixed(int node, bool fixed);
  bool is_node_fixed(int node) const;
  /// Pinned nodes in increasing order.
  std::vector<int> fixed_nodes() const;

  /// Moves every node rigidly so that the pose becomes this (velocities are kept).
  void set_pose(const Eigen::Isometry3d& pose) override;

 private:
  friend class Model;
  friend class physics::PhysicsWorld;
  SoftBody(Model& model, const SoftBodySpec& spec, int id);
  void check_node(int node) const;
  /// Copies the nodes from physics into positions_ and the pose's position onto their centroid.
  void sync();

  SoftBodySpec spec_;
  std::vector<double> positions_;
  std::vector<std::uint32_t> triangles_;
};

}  // namespace ambfplus
