#include "ambfplus/haptics/drill.h"
#include "ambfplus/errors.h"

#include <time.h>
#include <algorithm>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/rigid_body.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/scene/world.h"
#include "ambfplus/volume/label_table.h"
#include "ambfplus/volume/structure_distances.h"
#include "util/clock.h"

namespace ambfplus {
namespace {

using util::thread_cpu_seconds;
constexpr double kPi = 3.14159265358979323846;
// Metres a burr may sit inside a hard stop before it stops cutting (rounding of the held goal).
constexpr double kStopTolerance = 1e-6;

}  // namespace

Drill& add_drill(Model& model, const DrillSpec& spec) {
  auto lock = model.world().lock_state();  // claim, build and adopt as one
  const int id = model.claim_name(spec.name, "drill");
  return model.adopt(std::unique_ptr<Drill>(new Drill(model, spec, id)));
}

Drill::Drill(Model& model, const DrillSpec& spec, int id)
    : Object(model, spec.name, id), volume_(spec.volume), spec_(spec), burr_(spec.burr) {
  const std::string who = "drill '" + spec.name + "': ";
  if (volume_ == nullptr) throw ArgumentError(who + "needs a volume to drill");
  if (&volume_->world() != &model.world()) {
    throw ArgumentError(who + "its volume must be in the same world");
  }
  spec_.validate();
  if (spec_.shaft_radii.empty()) {
    for (int i = 1; i < spec_.cursors; ++i) spec_.shaft_radii.push_back(0.00065 + 0.0001 * (i - 1));
  }
  set_stiffness(spec_.stiffness);
  set_cutting_rate(spec_.cutting_rate);
  set_burr(spec_.burr);
  collider_ = std::make_unique<VoxelCollider>(volume_->data());
  // Every critical structure gets a field wide enough for the largest burr to see kExactReach.
  const VolumeData& data = *volume_->data();
  half_voxel_ = 0.5 * std::cbrt(data.voxel_size().prod());
  const double largest_burr =
      *std::max_element(spec_.burr_diameters.begin(), spec_.burr_diameters.end()) / 2;
  field_band_ = kExactReach + largest_burr + data.voxel_size().norm();
  structures_ = std::make_unique<StructureDistances>(data);
  for (const Label& l : data.label_table().labels()) {
    if (!l.critical) continue;
    critical_labels_.push_back(l.id);
    structures_->track(l.id, field_band_);
  }
  uncuttable_.assign(65536, false);
  hardness_.assign(65536, 1.0);
  cursors_.resize(spec_.cursors);
  for (int i = 0; i < spec_.cursors; ++i) {
    cursors_[i].set_radius(i == 0 ? burr_radius() : spec_.shaft_radii[i - 1]);
  }
  place(checked_pose(spec_.pose));
  set_fixtures(spec_.fixtures);
}

Drill::~Drill() = default;

void Drill::place(const Eigen::Isometry3d& pose) {
  set_goal(pose);
  const Eigen::Isometry3d volume_from_world = volume_->pose().inverse();
  const Eigen::Vector3d tip = volume_from_world * goal_.translation();
  const Eigen::Vector3d axis = volume_from_world.linear() * goal_.linear().col(0);
  for (int i = 0; i < spec_.cursors; ++i) cursors_[i].reset(tip + axis * (spec_.spacing * i));
  last_goal_position_ = goal_.translation();
  held_valid_ = false;  // a jump: the stops hold the goal from here on
  fixture_energy_ = 0.0;
  set_pose(goal_);
}

void Drill::set_goal(const Eigen::Isometry3d& goal) {
  if (!goal.matrix().allFinite()) throw ArgumentError("drill goal must be finite");
  goal_ = goal;
}

void Drill::set_speed(double speed) {
  if (!(speed >= 0.0 && speed <= 1.0)) throw ArgumentError("drill speed must be in 0..1");
  speed_ = speed;
}

void Drill::set_burr(int index) {
  if (index < 0 || index >= static_cast<int>(spec_.burr_diameters.size())) {
    throw ArgumentError("burr index must be 0.." + std::to_string(spec_.burr_diameters.size() - 1));
  }
  burr_ = index;
  if (!cursors_.empty()) cursors_[0].set_radius(burr_radius());
}

void Drill::set_voxels_per_step(int burr, int count) {
  if (burr < 0 || burr >= static_cast<int>(spec_.voxels_per_step.size()) || count < 1) {
    throw ArgumentError("voxels per step: burr must be 0.." +
                        std::to_string(spec_.voxels_per_step.size() - 1) + " and count >= 1");
  }
  spec_.voxels_per_step[burr] = count;
}

void Drill::set_stiffness(double k) {
  if (!(k > 0) || !std::isfinite(k)) throw ArgumentError("stiffness must be > 0 N/m");
  spec_.stiffness = k;
}

void Drill::set_cutting_rate(double rate) {
  if (!(rate >= 0) || !std::isfinite(rate)) throw ArgumentError("cutting rate must be >= 0");
  spec_.cutting_rate = rate;
}

void Drill::set_hardness(std::uint16_t label, double hardness) {
  if (!(hardness > 0) || !std::isfinite(hardness)) throw ArgumentError("hardness must be > 0");
  hardness_[label] = hardness;
}

void Drill::set_waypoints(const std::vector<DrillWaypoint>& waypoints) {
  double last = 0;
  for (const DrillWaypoint& w : waypoints) {
    if (!(w.time >= last)) throw ArgumentError("waypoint times must not decrease from 0");
    if (!(w.speed >= 0 && w.speed <= 1)) throw ArgumentError("waypoint speed must be 0..1");
    checked_pose(w.pose, describe() + " waypoint");
    last = w.time;
  }
  waypoints_.clear();
  if (waypoints.empty()) return;
  // Start from where the goal is now.
  waypoints_.push_back(DrillWaypoint{0.0, goal_.matrix(), on_, speed_});
  waypoints_.insert(waypoints_.end(), waypoints.begin(), waypoints.end());
  waypoint_clock_ = 0.0;
}

void Drill::attach(RigidBody& body, const Eigen::Isometry3d& offset) {
  body.set_kinematic(true);  // the drill carries it
  attached_.emplace_back(&body, offset);
  body.set_pose(pose() * offset);
  meshes_stale_ = true;  // rebuild the mesh collider without it
}

void Drill::sync_meshes() {
  if (meshes_stale_) {
    meshes_stale_ = false;
    const std::vector<Object*> objects = volume_->world().objects();
    meshes_.clear();
    mesh_bodies_.clear();
    for (Object* o : objects) {
      auto* body = dynamic_cast<RigidBody*>(o);
      // Ghosts touch nothing, the drill's cursors included.
      if (body == nullptr || !body->visual_mesh() || !body->collision().enabled ||
          is_ghost(*body)) {
        continue;
      }
      const bool carried = std::any_of(attached_.begin(), attached_.end(),
                                       [&](const auto& a) { return a.first == body; });
      if (carried) continue;
      if (body->shape().kind == Shape::Kind::kPlane) {
        meshes_.add_plane();
      } else {
        meshes_.add_mesh(*body->visual_mesh());
      }
      mesh_bodies_.push_back(body);
    }
  }
  const Eigen::Isometry3d volume_from_world = volume_->pose().inverse();
  for (std::size_t i = 0; i < mesh_bodies_.size(); ++i) {
    meshes_.set_pose(static_cast<int>(i), volume_from_world * mesh_bodies_[i]->pose());
  }
}

void Drill::follow_waypoints() {
  if (waypoints_.empty()) return;
  std::size_t n = 0;
  while (n + 1 < waypoints_.size() && waypoints_[n + 1].time <= waypoint_clock_) ++n;
  const DrillWaypoint& a = waypoints_[n];
  Eigen::Isometry3d pose = checked_pose(a.pose);
  on_ = a.on;
  speed_ = a.speed;
  if (n + 1 < waypoints_.size()) {
    const DrillWaypoint& b = waypoints_[n + 1];
    const double f = (waypoint_clock_ - a.time) / std::max(b.time - a.time, 1e-12);
    const Eigen::Isometry3d pb = checked_pose(b.pose);
    pose.translation() = (1 - f) * pose.translation() + f * pb.translation();
    pose.linear() = Eigen::Quaterniond(pose.linear())
                        .slerp(f, Eigen::Quaterniond(pb.linear()))
                        .toRotationMatrix();
  }
  goal_ = pose;
}

void Drill::tick(double dt, std::int64_t step) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  follow_waypoints();
  waypoint_clock_ += dt;
  age_ += dt;
  collider_->sync();
  sync_meshes();
  structures_->tick(!realtime_);  // fields follow the edits (see StructureDistances)
  update_cursors();
  place_drill();
  const Eigen::Vector3d tip_force = update_forces(dt);
  remove_tissue(dt, step, tip_force);
  update_critical_distances();
  record_timing(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                thread_cpu_seconds() - cpu_start);
}

void Drill::update_cursors() {
  // Cursor goals along the shaft, in the volume frame; the one furthest from its goal leads.
  const Eigen::Isometry3d volume_from_world = volume_->pose().inverse();
  // The hard stops hold the whole drill back, the shaft with the tip.
  const Eigen::Vector3d tip_goal = held_tip_goal(volume_from_world * goal_.translation());
  const Eigen::Vector3d axis = volume_from_world.linear() * goal_.linear().col(0);
  double largest = -1;
  for (int i = 0; i < cursor_count(); ++i) {
    cursors_[i].update(*collider_, tip_goal + axis * (spec_.spacing * i), spec_.friction, &meshes_);
    const double error = (cursors_[i].proxy() - cursors_[i].goal()).norm();
    if (error > largest + 1e-12) {
      largest = error;
      leading_ = i;
    }
  }
}

void Drill::place_drill() {
  // The drill sits where its leading cursor's proxy puts it, its meshes with it (or at the goal).
  const Eigen::Vector3d axis = volume_->pose().inverse().linear() * goal_.linear().col(0);
  const Eigen::Vector3d tip = cursors_[leading_].proxy() - axis * (spec_.spacing * leading_);
  Eigen::Isometry3d pose = goal_;
  pose.translation() = volume_->pose() * tip;
  set_pose(pose);
  const Eigen::Isometry3d& carrier = meshes_follow_goal_ ? goal_ : pose;
  for (auto& [body, offset] : attached_) body->set_pose(carrier * offset);
}

Eigen::Vector3d Drill::update_forces(double dt) {
  // Stiffness times proxy - goal, damped against the goal's motion while in contact, limited,
  // and ramped in over the soft start.
  const Eigen::Matrix3d world_from_volume = volume_->pose().linear();
  const Eigen::Vector3d goal_velocity =
      dt > 0 ? Eigen::Vector3d((goal_.translation() - last_goal_position_) / dt)
             : Eigen::Vector3d::Zero();
  last_goal_position_ = goal_.translation();
  const double ramp = spec_.soft_start > 0 ? std::min(1.0, age_ / spec_.soft_start) : 1.0;
  auto limited = [&](Eigen::Vector3d f) {
    const double m = f.norm();
    if (m > spec_.max_force) f *= spec_.max_force / m;
    return f * ramp;
  };
  total_force_.setZero();
  Eigen::Vector3d tip_force_volume = Eigen::Vector3d::Zero();
  for (int i = 0; i < cursor_count(); ++i) {
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    if (cursors_[i].contacts() > 0) {
      f = world_from_volume * (spec_.stiffness * (cursors_[i].proxy() - cursors_[i].goal())) -
          spec_.damping * goal_velocity;
    }
    f = limited(f);
    total_force_ += f;
    if (i == leading_) force_ = f;
    if (i == 0) tip_force_volume = world_from_volume.transpose() * f;
  }
  // Held back by a hard stop, the tip still presses on the tissue with the hand's whole push:
  // the stop holds the burr, not the force it cuts with.
  if (any_stop_ && held_valid_ && cursors_[0].contacts() > 0) {
    const Eigen::Vector3d hand = volume_->pose().inverse() * goal_.translation();
    tip_force_volume =
        world_from_volume.transpose() *
        limited(world_from_volume * (spec_.stiffness * (cursors_[0].proxy() - hand)));
  }
  total_force_ = limited(total_force_);
  fixture_force_ = update_fixture_force(dt, goal_velocity);
  force_ += fixture_force_;
  total_force_ += fixture_force_;
  return tip_force_volume;
}

std::vector<std::pair<double, std::array<int, 3>>> Drill::cuttable_voxels() const {
  const ProxyCursor& burr = cursors_[0];
  const std::shared_ptr<VolumeData>& data = volume_->data();
  // The burr cuts what it touches: voxels whose centres are within a little more than half a
  // voxel of its surface (where the proxy holds it, touching the voxel spheres), those nearest
  // where the device pushes it first.
  const double reach = burr.radius() + 0.6 * data->voxel_size().maxCoeff();
  // The proxy does not overlap the solid, so what it touches is surface, which the proxy's
  // last patch holds (it reaches at least the burr radius and four voxel radii beyond where the
  // proxy started; the proxy moved towards the goal, inside that).
  const SurfacePatch& patch = burr.patch();
  const bool covered = (burr.proxy() - patch.centre).norm() + reach <= patch.radius;
  const std::vector<std::array<int, 3>> gathered =
      covered ? std::vector<std::array<int, 3>>() : collider_->surface_within(burr.proxy(), reach);
  const std::vector<std::array<int, 3>>& candidates = covered ? patch.voxels : gathered;
  std::vector<std::pair<double, std::array<int, 3>>> order;
  for (std::size_t n = 0; n < candidates.size(); ++n) {
    const std::array<int, 3>& v = candidates[n];
    // Distance first (the patch holds the centres), the grid only for voxels in reach.
    const Eigen::Vector3d c = covered ? Eigen::Vector3d(patch.x[n], patch.y[n], patch.z[n])
                                      : data->voxel_center(v[0], v[1], v[2]);
    if ((c - burr.proxy()).squaredNorm() > reach * reach) continue;
    const std::uint16_t label = data->label(v[0], v[1], v[2]);
    if (label == 0 || uncuttable_[label]) continue;  // removed earlier, or behind a hard stop
    if (plan_stop_ &&
        (*plan_mask_)[static_cast<std::size_t>(v[0]) +
                      static_cast<std::size_t>(data->shape()[0]) *
                          (v[1] + static_cast<std::size_t>(data->shape()[1]) * v[2])] == 0) {
      continue;  // outside the plan
    }
    const Label* l = data->label_table().find(label);
    if (l != nullptr && !l->removable) continue;
    order.push_back({(c - burr.goal()).squaredNorm(), v});
  }
  // Nearest the goal first; ties by index, so the order is the same every run.
  std::sort(order.begin(), order.end());
  return order;
}

void Drill::remove_tissue(double dt, std::int64_t step, const Eigen::Vector3d& tip_force_volume) {
  // Only the tip cuts, only when it leads, touches the anatomy and the drill runs.
  const ProxyCursor& burr = cursors_[0];
  bool on_anatomy = false;  // a mesh contact alone cuts nothing
  for (int i = 0; i < burr.contacts(); ++i) on_anatomy |= burr.contact_voxel(i)[0] >= 0;
  // Nothing is cut while the burr is within a hard stop (the held goal keeps it at the edge).
  const bool stopped = any_stop_ && stop_clearance(burr.proxy(), nullptr) < -kStopTolerance;
  if (!(on_ && speed_ > 0 && leading_ == 0 && on_anatomy) || stopped) {
    budget_ = 0;
    return;
  }
  const std::shared_ptr<VolumeData>& data = volume_->data();
  const std::vector<std::pair<double, std::array<int, 3>>> order = cuttable_voxels();
  std::vector<std::array<int, 3>> take;
  if (spec_.removal == RemovalMode::kCompatible) {
    const std::size_t n = std::min<std::size_t>(order.size(), spec_.voxels_per_step[burr_]);
    for (std::size_t i = 0; i < n; ++i) take.push_back(order[i].second);
  } else {
    // A volume budget from the normal force, spent on whole voxels by their hardness.
    const double normal_force = std::abs(tip_force_volume.dot(burr.mean_normal()));
    const double voxel_volume = data->voxel_size().prod();
    const double cap = 4.0 / 3.0 * kPi * std::pow(burr.radius(), 3);
    budget_ = std::min(cap, budget_ + spec_.cutting_rate * speed_ * normal_force * dt);
    for (const auto& [d2, v] : order) {
      const double cost = voxel_volume * hardness_[data->label(v[0], v[1], v[2])];
      if (cost > budget_) break;
      budget_ -= cost;
      take.push_back(v);
    }
    if (order.empty()) budget_ = 0;
  }
  if (take.empty()) return;
  const std::int64_t before = data->revision();
  const std::vector<std::uint16_t> old = collider_->remove(take);
  // Fields of structures this cut did not touch skip its box.
  structures_->removed(before, take, old);
  for (std::size_t i = 0; i < take.size(); ++i) {
    log_removed(RemovedVoxel{step, take[i], old[i]});
    const Label* l = data->label_table().find(old[i]);
    if (l != nullptr && l->critical) log_event(DrillEvent{step, "critical", old[i], take[i]});
  }
}

void Drill::update_critical_distances() {
  // From the burr's surface to each critical structure.
  critical_distances_.clear();
  for (std::uint16_t label : critical_labels_) {
    const double d = surface_distance(label, cursors_[0].proxy(), nullptr);
    critical_distances_.emplace_back(label, std::max(0.0, d));
  }
}

void Drill::log_removed(const RemovedVoxel& voxel) {
  removed_.push_back(voxel);
  if (removed_.size() > kMaxRemoved) {
    removed_.pop_front();
    ++removed_dropped_;
  }
}

void Drill::log_event(const DrillEvent& event) {
  events_.push_back(event);
  if (events_.size() > kMaxEvents) {
    events_.pop_front();
    ++events_dropped_;
  }
}

void Drill::record_timing(double wall, double cpu) {
  tick_seconds_.push_back(wall);
  tick_cpu_seconds_.push_back(cpu);
  if (tick_seconds_.size() > kTickHistory) {
    tick_seconds_.pop_front();
    tick_cpu_seconds_.pop_front();
  }
}

Eigen::Vector3d Drill::cursor_proxy(int i) const {
  return volume_->pose() * cursors_.at(i).proxy();
}

Eigen::Vector3d Drill::cursor_goal(int i) const { return volume_->pose() * cursors_.at(i).goal(); }

Eigen::Vector3d Drill::tip_normal() const {
  return volume_->pose().linear() * cursors_[0].mean_normal();
}

std::deque<RemovedVoxel> Drill::take_removed() {
  std::deque<RemovedVoxel> out;
  auto lock = world().lock_state_for_copy();  // a real-time loop's step appends meanwhile
  out.swap(removed_);
  return out;
}

std::deque<DrillEvent> Drill::take_events() {
  std::deque<DrillEvent> out;
  auto lock = world().lock_state_for_copy();
  out.swap(events_);
  return out;
}

}  // namespace ambfplus
