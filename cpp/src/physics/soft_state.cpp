// SoftBody's physics side: the btSoftBody made from its nodes and triangles, and what it asks of
// Bullet.

#include <cstdint>
#include <stdexcept>
#include <unordered_set>

#include "ambfplus/errors.h"
#include "ambfplus/scene/soft_body.h"
#include "physics/physics_world.h"

namespace ambfplus {
namespace physics {
namespace {

// Voxel size of Bullet's signed-distance cache of rigid shapes, against which soft-body nodes
// collide. Bullet's 0.25 m suits metre-sized scenes; the distance is interpolated within a voxel,
// which is exact at a flat face only when the face is at least a voxel from the shape's other
// faces, so surgical scenes (centimetre objects, millimetre tools) need far smaller voxels.
constexpr btScalar kSdfVoxel = 0.005;

// Soft bodies against static planes, exactly. Bullet meets a plane as triangles cut to the soft
// body's bounds, which change as it moves while its distance cache keeps the old ones, so nodes
// float above planes or fall through them. This makes the same node contacts Bullet's SDF_RS
// collider makes, from the plane's exact signed distance.
class SoftPlaneCollision : public btCollisionAlgorithm {
 public:
  SoftPlaneCollision(const btCollisionAlgorithmConstructionInfo& info, bool swapped)
      : btCollisionAlgorithm(info), swapped_(swapped) {}

  void processCollision(const btCollisionObjectWrapper* a, const btCollisionObjectWrapper* b,
                        const btDispatcherInfo&, btManifoldResult*) override {
    const btCollisionObjectWrapper* soft = swapped_ ? b : a;
    const btCollisionObjectWrapper* plane = swapped_ ? a : b;
    auto* sb = const_cast<btSoftBody*>(btSoftBody::upcast(soft->getCollisionObject()));
    if (sb == nullptr || (sb->m_cfg.collisions & btSoftBody::fCollision::RVSmask) == 0) return;
    const auto* shape = static_cast<const btStaticPlaneShape*>(plane->getCollisionShape());
    const btTransform& t = plane->getWorldTransform();
    const btVector3 normal = t.getBasis() * shape->getPlaneNormal();
    const btScalar constant = shape->getPlaneConstant() + normal.dot(t.getOrigin());
    const btScalar margin = sb->getCollisionShape()->getMargin();
    const btCollisionObject* object = plane->getCollisionObject();
    const btRigidBody* rigid = btRigidBody::upcast(object);
    const btScalar inv_mass = rigid != nullptr ? rigid->getInvMass() : 0;
    const btScalar dt = sb->m_sst.sdt;
    const btScalar friction = sb->m_cfg.kDF * object->getFriction();
    const btScalar hardness = object->isStaticOrKinematicObject() ? sb->m_cfg.kKHR : sb->m_cfg.kCHR;
    const btMatrix3x3 no_inertia(0, 0, 0, 0, 0, 0, 0, 0, 0);
    const btMatrix3x3& inv_inertia =
        rigid != nullptr ? rigid->getInvInertiaTensorWorld() : no_inertia;
    for (int i = 0; i < sb->m_nodes.size(); ++i) {
      btSoftBody::Node& n = sb->m_nodes[i];
      const btScalar gap = normal.dot(n.m_x) - constant - margin;
      if (n.m_battach || gap >= 0 || n.m_im + inv_mass <= 0) continue;
      btSoftBody::RContact c;
      c.m_cti.m_colObj = object;
      c.m_cti.m_normal = normal;
      c.m_cti.m_offset = -(constant + margin);
      const btVector3 ra = n.m_x - t.getOrigin();
      const btVector3 va =
          rigid != nullptr ? rigid->getVelocityInLocalPoint(ra) * dt : btVector3(0, 0, 0);
      const btVector3 vr = (n.m_x - n.m_q) - va;
      const btScalar dn = vr.dot(normal);
      const btVector3 tangential = vr - normal * dn;
      // The impulse matrix of a node against a body of inverse mass and inertia (Bullet's).
      btMatrix3x3 k = btMatrix3x3::getIdentity().scaled(btVector3(1, 1, 1) * (n.m_im + inv_mass));
      const btMatrix3x3 cross(0, -ra.z(), ra.y(), ra.z(), 0, -ra.x(), -ra.y(), ra.x(), 0);
      k = k - cross * inv_inertia * cross;
      c.m_node = &n;
      c.m_c0 = k.inverse() * (1 / dt);
      c.m_c1 = ra;
      c.m_c2 = n.m_im * dt;
      c.m_c3 = tangential.length2() < dn * friction * dn * friction ? 0 : 1 - friction;
      c.m_c4 = hardness;
      c.t1 = c.t2 = btVector3(0, 0, 0);  // (multibody contacts only)
      sb->m_rcontacts.push_back(c);
    }
  }

  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return 1;
  }
  void getAllContactManifolds(btManifoldArray&) override {}

  struct CreateFunc : btCollisionAlgorithmCreateFunc {
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& info,
                                                   const btCollisionObjectWrapper*,
                                                   const btCollisionObjectWrapper*) override {
      void* memory = info.m_dispatcher1->allocateCollisionAlgorithm(sizeof(SoftPlaneCollision));
      return new (memory) SoftPlaneCollision(info, m_swapped);
    }
  };

 private:
  bool swapped_;
};

void register_soft_plane_collision(btCollisionDispatcher& dispatcher) {
  static SoftPlaneCollision::CreateFunc soft_plane;
  static SoftPlaneCollision::CreateFunc plane_soft;
  plane_soft.m_swapped = true;
  dispatcher.registerCollisionCreateFunc(SOFTBODY_SHAPE_PROXYTYPE, STATIC_PLANE_PROXYTYPE,
                                         &soft_plane);
  dispatcher.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, SOFTBODY_SHAPE_PROXYTYPE,
                                         &plane_soft);
}

}  // namespace

Soft::~Soft() {
  if (world != nullptr && body) world->removeSoftBody(body.get());
}

void PhysicsWorld::add(SoftBody& sb) {
  const SoftBodySpec& spec = sb.spec();
  const SoftBodyConfig& k = spec.config;
  const int count = static_cast<int>(sb.node_count());
  std::vector<btVector3> x(count);
  for (int i = 0; i < count; ++i) x[i] = to_bullet(sb.node_position(i));
  auto s = std::make_unique<Soft>();
  s->body = std::make_unique<btSoftBody>(&world_->getWorldInfo(), count, x.data(), nullptr);
  btSoftBody& b = *s->body;

  // A link along every triangle edge (once), and the faces.
  const std::vector<std::uint32_t>& tri = sb.triangles();
  std::unordered_set<std::uint64_t> linked;
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tri[t + e], c = tri[t + (e + 1) % 3];
      const std::uint64_t key = (std::uint64_t(std::min(a, c)) << 32) | std::max(a, c);
      if (linked.insert(key).second) b.appendLink(int(a), int(c));
    }
    b.appendFace(int(tri[t]), int(tri[t + 1]), int(tri[t + 2]));
  }

  btSoftBody::Material& m = *b.m_materials[0];
  m.m_kLST = k.linear_stiffness;
  m.m_kAST = k.area_stiffness;
  m.m_kVST = k.volume_stiffness;
  btSoftBody::Config& cfg = b.m_cfg;
  cfg.kVCF = k.velocity_correction;
  cfg.kDP = k.damping;
  cfg.kDG = k.drag;
  cfg.kLF = k.lift;
  cfg.kPR = k.pressure;
  cfg.kVC = k.volume_conservation;
  cfg.kDF = k.dynamic_friction;
  cfg.kMT = k.pose_matching.value_or(0.0);
  cfg.kCHR = k.rigid_hardness;
  cfg.kKHR = k.kinetic_hardness;
  cfg.kSHR = k.soft_hardness;
  cfg.kAHR = k.anchor_hardness;
  cfg.kSRHR_CL = k.cluster_rigid_hardness;
  cfg.kSKHR_CL = k.cluster_kinetic_hardness;
  cfg.kSSHR_CL = k.cluster_soft_hardness;
  cfg.kSR_SPLT_CL = k.cluster_rigid_impulse_split;
  cfg.kSK_SPLT_CL = k.cluster_kinetic_impulse_split;
  cfg.kSS_SPLT_CL = k.cluster_soft_impulse_split;
  cfg.maxvolume = k.max_volume;
  cfg.timescale = k.time_scale;
  cfg.viterations = k.velocity_iterations;
  cfg.piterations = k.position_iterations;
  cfg.diterations = k.drift_iterations;
  cfg.citerations = k.cluster_iterations;
  cfg.collisions = k.collision_flags;
  if (k.bending_constraint) b.generateBendingConstraints(*k.bending_constraint, &m);

  // Mass shared evenly (not by area), then the pinned nodes made immovable.
  b.setTotalMass(spec.mass, false);
  s->node_mass = spec.mass / count;
  for (int n : k.fixed_nodes) b.setMass(n, 0);
  // The rest shape, for pose matching and volume conservation (which needs the rest volume).
  if (k.pose_matching || k.volume_conservation > 0) {
    b.setPose(k.volume_conservation > 0, k.pose_matching.has_value());
  }
  if (k.clusters) b.generateClusters(*k.clusters);
  if (spec.randomize_constraints) b.randomizeConstraints();
  b.getCollisionShape()->setMargin(spec.margin);
  b.setUserPointer(&sb);

  btSoftBodyWorldInfo& info = world_->getWorldInfo();
  if (world_->getSoftBodyArray().size() == 0 && info.m_sparsesdf.m_defaultVoxelsz != kSdfVoxel) {
    info.m_sparsesdf.setDefaultVoxelsz(kSdfVoxel);
    info.m_sparsesdf.Reset();
    register_soft_plane_collision(*dispatcher_);
  }
  b.updateNormals();
  world_->addSoftBody(&b);
  s->world = world_.get();
  sb.set_physics_state(std::move(s));
  sb.sync();
}

bool PhysicsWorld::soft_bodies_move() const {
  const btSoftBodyArray& softs = world_->getSoftBodyArray();
  for (int i = 0; i < softs.size(); ++i) {
    const btSoftBody& b = *softs[i];
    for (int n = 0; n < b.m_nodes.size(); ++n) {
      if (b.m_nodes[n].m_im > 0) return true;
    }
  }
  return false;
}

void PhysicsWorld::sync_soft_bodies() {
  btSoftBodyArray& softs = world_->getSoftBodyArray();
  if (softs.size() == 0) return;
  for (int i = 0; i < softs.size(); ++i) static_cast<SoftBody*>(softs[i]->getUserPointer())->sync();
  // Distances to shapes no node came near for a while are dropped.
  world_->getWorldInfo().m_sparsesdf.GarbageCollect();
}

}  // namespace physics

void SoftBody::sync() {
  const btSoftBody& b = *physics::soft_of(*this)->body;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int n = 0; n < b.m_nodes.size(); ++n) {
    const btVector3& x = b.m_nodes[n].m_x;
    double* p = positions_.data() + 3 * n;
    p[0] = x.x();
    p[1] = x.y();
    p[2] = x.z();
    centroid += Eigen::Vector3d(p[0], p[1], p[2]);
  }
  Eigen::Isometry3d pose = this->pose();
  pose.translation() = centroid / static_cast<double>(b.m_nodes.size());
  Object::set_pose(pose);
}

std::vector<double> SoftBody::node_velocities() const {
  const btSoftBody& b = *physics::soft_of(*this)->body;
  std::vector<double> out(3 * b.m_nodes.size());
  for (int n = 0; n < b.m_nodes.size(); ++n) {
    const btVector3& v = b.m_nodes[n].m_v;
    out[3 * n] = v.x();
    out[3 * n + 1] = v.y();
    out[3 * n + 2] = v.z();
  }
  return out;
}

void SoftBody::set_node_position(int node, const Eigen::Vector3d& position) {
  check_node(node);
  if (!position.allFinite()) {
    throw ArgumentError("soft body '" + name() + "': node positions must be finite");
  }
  btSoftBody& b = *physics::soft_of(*this)->body;
  btSoftBody::Node& n = b.m_nodes[node];
  n.m_x = physics::to_bullet(position);
  n.m_q = n.m_x;
  b.updateNormals();
  b.updateBounds();
  sync();
}

void SoftBody::set_node_fixed(int node, bool fixed) {
  check_node(node);
  btSoftBody& b = *physics::soft_of(*this)->body;
  if (fixed) {
    b.setMass(node, 0);
    b.m_nodes[node].m_v.setZero();
  } else {
    b.setMass(node, physics::soft_of(*this)->node_mass);
  }
}

bool SoftBody::is_node_fixed(int node) const {
  check_node(node);
  return physics::soft_of(*this)->body->m_nodes[node].m_im == 0;
}

std::vector<int> SoftBody::fixed_nodes() const {
  std::vector<int> out;
  const btSoftBody& b = *physics::soft_of(*this)->body;
  for (int n = 0; n < b.m_nodes.size(); ++n) {
    if (b.m_nodes[n].m_im == 0) out.push_back(n);
  }
  return out;
}

void SoftBody::set_pose(const Eigen::Isometry3d& pose) {
  if (physics::soft_of(*this) == nullptr) {
    Object::set_pose(pose);
    return;
  }
  const btTransform move = physics::to_bullet(Eigen::Isometry3d(pose * this->pose().inverse()));
  btSoftBody& b = *physics::soft_of(*this)->body;
  for (int n = 0; n < b.m_nodes.size(); ++n) {
    b.m_nodes[n].m_x = move * b.m_nodes[n].m_x;
    b.m_nodes[n].m_q = move * b.m_nodes[n].m_q;
  }
  b.updateNormals();
  b.updateBounds();
  Object::set_pose(pose);
  sync();
}

}  // namespace ambfplus
