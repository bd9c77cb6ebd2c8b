// The drill's virtual fixtures: forbidden regions around structures, on their distance fields.

#include <algorithm>
#include <cmath>
#include <limits>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/volume/label_table.h"
#include "ambfplus/volume/structure_distances.h"

namespace ambfplus {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The hard stops' friction: the burr slides along a stop only where the hand is further along
// its surface than into it.
constexpr double kStopFriction = 1.0;

}  // namespace

void Drill::set_fixture(const FixtureSpec& fixture) {
  std::vector<FixtureSpec> all = fixtures();
  const LabelTable& table = volume_->data()->label_table();
  const std::uint16_t label = resolve_label(table, fixture.structure, describe() + " fixture");
  auto same = [&](const FixtureSpec& f) {
    return resolve_label(table, f.structure, "fixture") == label;
  };
  auto it = std::find_if(all.begin(), all.end(), same);
  if (it != all.end()) {
    *it = fixture;
  } else {
    all.push_back(fixture);
  }
  set_fixtures(all);
}

void Drill::set_fixtures(const std::vector<FixtureSpec>& fixtures) {
  // Everything is checked and every field built before anything changes.
  const LabelTable& table = volume_->data()->label_table();
  const std::string who = describe() + ": ";
  std::vector<ActiveFixture> next;
  for (const FixtureSpec& f : fixtures) {
    f.validate(who);
    const std::uint16_t label = resolve_label(table, f.structure, describe() + " fixture");
    for (const ActiveFixture& a : next) {
      if (a.label == label) {
        throw ArgumentError(who + "two fixtures for structure '" + a.spec.structure + "'");
      }
    }
    ActiveFixture a{f, label};
    if (const Label* l = table.find(label)) a.spec.structure = l->name;
    next.push_back(a);
  }
  const double largest_burr =
      *std::max_element(spec_.burr_diameters.begin(), spec_.burr_diameters.end()) / 2;
  const double diagonal = volume_->data()->voxel_size().norm();
  for (const ActiveFixture& a : next) {
    const double reach = std::max(a.spec.start, a.spec.stop) + largest_burr + 2 * diagonal;
    structures_->track(a.label, std::max(field_band_, reach));
  }
  fixtures_ = std::move(next);
  fixtures_changed();
}

std::vector<FixtureSpec> Drill::fixtures() const {
  std::vector<FixtureSpec> out;
  for (const ActiveFixture& a : fixtures_) out.push_back(a.spec);
  return out;
}

void Drill::set_plan(const std::vector<std::uint8_t>& mask, const FixtureSpec& fixture) {
  const VolumeData& data = *volume_->data();
  if (static_cast<std::int64_t>(mask.size()) != data.voxel_count()) {
    throw ArgumentError(describe() + ": a plan needs one entry per voxel (" +
                        std::to_string(data.voxel_count()) + "), got " +
                        std::to_string(mask.size()));
  }
  FixtureSpec spec = fixture;
  spec.structure = "plan";
  spec.validate(describe() + ": ");
  auto shared = std::make_shared<const std::vector<std::uint8_t>>(mask);
  plan_voxels_ = static_cast<std::int64_t>(mask.size()) -
                 static_cast<std::int64_t>(std::count(mask.begin(), mask.end(), 0));
  const double largest_burr =
      *std::max_element(spec_.burr_diameters.begin(), spec_.burr_diameters.end()) / 2;
  const double reach =
      std::max(spec.start, spec.stop) + largest_burr + 2 * data.voxel_size().norm();
  structures_->set_plan(shared);
  structures_->track(0, reach);
  plan_mask_ = std::move(shared);
  plan_ = ActiveFixture{spec, 0};
  fixtures_changed();
}

void Drill::set_plan(const std::vector<std::string>& labels, const FixtureSpec& fixture) {
  const VolumeData& data = *volume_->data();
  std::vector<bool> wanted(65536, false);
  for (const std::string& name : labels) {
    wanted[resolve_label(data.label_table(), name, describe() + " plan")] = true;
  }
  const auto& n = data.shape();
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(data.voxel_count()));
  std::size_t idx = 0;
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) mask[idx++] = wanted[data.label(i, j, k)] ? 1 : 0;
    }
  }
  set_plan(mask, fixture);
}

void Drill::follow_plan(double max_force, double start, bool enabled) {
  const std::string who = describe() + ": follow_plan: ";
  if (!std::isfinite(max_force) || max_force < 0) {
    throw ArgumentError(who + "max_force must be a finite number of newtons >= 0, got " +
                        std::to_string(max_force));
  }
  if (!std::isfinite(start) || start <= 0) {
    throw ArgumentError(who + "start must be a positive number of metres, got " +
                        std::to_string(start));
  }
  if (!plan_mask_) throw ArgumentError(who + "there is no plan to follow (set_plan first)");
  const double largest_burr =
      *std::max_element(spec_.burr_diameters.begin(), spec_.burr_diameters.end()) / 2;
  structures_->track(StructureDistances::kPlanTarget,
                     3 * start + largest_burr + 2 * volume_->data()->voxel_size().norm());
  follow_ = Follow{enabled, max_force, start};
  fixtures_changed();
}

void Drill::clear_plan() {
  follow_ = Follow{};
  plan_.reset();
  plan_mask_.reset();
  plan_voxels_ = 0;
  fixtures_changed();
}

void Drill::set_plan_enabled(bool enabled) {
  if (!plan_)
    throw ArgumentError(describe() + ": set_plan_enabled: there is no plan (set_plan first)");
  plan_->spec.enabled = enabled;
  fixtures_changed();
}

void Drill::fixtures_changed() {
  std::fill(uncuttable_.begin(), uncuttable_.end(), false);
  any_stop_ = false;
  active_.clear();
  for (const ActiveFixture& a : fixtures_) {
    if (!a.spec.enabled) continue;
    active_.push_back(&a);
    if (a.spec.stop > 0) {
      uncuttable_[a.label] = true;
      any_stop_ = true;
    }
  }
  plan_stop_ = plan_ && plan_->spec.enabled && plan_->spec.stop > 0;
  if (plan_ && plan_->spec.enabled) active_.push_back(&*plan_);
  any_stop_ = any_stop_ || plan_stop_;
  held_valid_ = false;
  fixture_energy_ = 0.0;  // new regions: the energy observer starts anew
}

double Drill::surface_distance(int label, const Eigen::Vector3d& p, Eigen::Vector3d* away) const {
  Eigen::Vector3d g;
  const double d = structures_->distance(label, p, &g) - burr_radius() - half_voxel_;
  if (away != nullptr) {
    const double n = g.norm();
    *away = n > 1e-9 ? Eigen::Vector3d(g / n) : Eigen::Vector3d::Zero();
  }
  return d;
}

double Drill::structure_distance(std::uint16_t label, const Eigen::Vector3d& p) const {
  if (label == 0 || !structures_->tracks(label)) {
    throw ArgumentError(describe() + ": label " + std::to_string(label) +
                        " is neither critical nor fixed");
  }
  return surface_distance(label, p, nullptr);
}

double Drill::stop_clearance(const Eigen::Vector3d& p, Eigen::Vector3d* away) const {
  double best = kInf;
  for (const ActiveFixture* a : active_) {
    if (a->spec.stop <= 0) continue;
    Eigen::Vector3d n;
    const double c = surface_distance(a->label, p, &n) - a->spec.stop;
    if (c < best) {
      best = c;
      if (away != nullptr) *away = n;
    }
  }
  return best;
}

Eigen::Vector3d Drill::held_tip_goal(const Eigen::Vector3d& goal) {
  if (!any_stop_) {
    held_valid_ = false;
    return goal;
  }
  if (!held_valid_) {
    held_goal_ = goal;
    held_valid_ = true;
    return goal;
  }
  // The furthest point of from -> to whose clearance stays >= 0 (or, from inside a stop, does
  // not fall), found by steps of half a voxel and then bisection; sets the surface's normal.
  const double step = 0.5 * volume_->data()->voxel_size().minCoeff();
  auto march = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                   Eigen::Vector3d* normal) -> Eigen::Vector3d {
    const double c0 = stop_clearance(from, normal);
    const double floor = std::min(0.0, c0);
    const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / step)));
    double lo = 0.0;
    for (int i = 1; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      if (stop_clearance(from + t * (to - from), nullptr) >= floor) {
        lo = t;
        continue;
      }
      double hi = t;
      for (int b = 0; b < 12; ++b) {
        const double mid = 0.5 * (lo + hi);
        (stop_clearance(from + mid * (to - from), nullptr) >= floor ? lo : hi) = mid;
      }
      const Eigen::Vector3d hit = from + lo * (to - from);
      stop_clearance(hit, normal);
      return hit;
    }
    normal->setZero();
    return to;
  };
  Eigen::Vector3d normal;
  const Eigen::Vector3d hit = march(held_goal_, goal, &normal);
  if (normal.isZero()) {
    held_goal_ = hit;
  } else {
    // Slide along the stop's surface as on a wall with friction (coefficient kStopFriction):
    // only where the hand is further along the surface than into it, and only by the excess,
    // so pushing straight on (or at a slant) holds the burr where it met the stop.
    const Eigen::Vector3d rest = goal - hit;
    const double into = std::max(0.0, -rest.dot(normal));
    const Eigen::Vector3d along = rest + std::min(0.0, rest.dot(normal)) * normal;
    const double excess = along.norm() - kStopFriction * into;
    if (excess > 0) {
      Eigen::Vector3d ignored;
      held_goal_ = march(hit, hit + along * (excess / along.norm()), &ignored);
    } else {
      held_goal_ = hit;
    }
  }
  return held_goal_;
}

Eigen::Vector3d Drill::fixture_push(const Eigen::Vector3d& centre) const {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (const ActiveFixture* a : active_) {
    if (a->spec.max_force <= 0) continue;
    Eigen::Vector3d away;
    const double d = surface_distance(a->label, centre, &away);
    if (d >= a->spec.start) continue;
    f += a->spec.max_force * (1.0 - std::max(d, 0.0) / a->spec.start) * away;
  }
  if (follow_.enabled && follow_.max_force > 0) {
    Eigen::Vector3d away;
    const double d = surface_distance(StructureDistances::kPlanTarget, centre, &away);
    const double s = follow_.start;
    // Rising over [0, s], held to 2 s, falling to zero at 3 s (within the field's band).
    const double scale = std::clamp(std::min(d / s, 3.0 - d / s), 0.0, 1.0);
    if (std::isfinite(d)) f -= follow_.max_force * scale * away;
  }
  return f;
}

Eigen::Vector3d Drill::update_fixture_force(double dt, const Eigen::Vector3d& goal_velocity) {
  const Eigen::Matrix3d world_from_volume = volume_->pose().linear();
  // The energy the fixtures took from the hand over the last tick: their held force times the
  // hand's motion (the hand feels -force . motion as work done on the fixtures).
  fixture_energy_ -= fixture_force_.dot(goal_velocity) * dt;
  Eigen::Vector3d f = fixture_push(cursors_[0].proxy());
  // A hard stop holding the goal back: the drill's spring between the hand and the held goal.
  if (any_stop_ && held_valid_) {
    const Eigen::Vector3d tip_goal = volume_->pose().inverse() * goal_.translation();
    f += spec_.stiffness * (held_goal_ - tip_goal);
  }
  f = world_from_volume * f;
  if (f.norm() > spec_.max_force) f *= spec_.max_force / f.norm();
  if (spec_.soft_start > 0) f *= std::min(1.0, age_ / spec_.soft_start);
  // The energy is kept across leaving a region: what a pass gave too much is taken back at
  // the next (forgiving it at each exit would let bounces in and out gain energy).
  if (fixture_passivity_ && dt > 0 && !f.isZero()) {
    // Were the hand to go on as it moved, would the fixtures have given more than they took?
    // Then damp its motion by just enough to dissipate the difference.
    const double v2 = goal_velocity.squaredNorm();
    const double predicted = fixture_energy_ - f.dot(goal_velocity) * dt;
    if (predicted < 0 && v2 > 1e-12) {
      Eigen::Vector3d damping = (predicted / (v2 * dt)) * goal_velocity;
      if (damping.norm() > spec_.max_force) damping *= spec_.max_force / damping.norm();
      f += damping;
    }
  }
  return f;
}

}  // namespace ambfplus
