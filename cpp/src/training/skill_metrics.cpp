#include "ambfplus/training/skill_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "ambfplus/errors.h"

namespace ambfplus {

namespace {

void check_non_negative(double value, const std::string& what) {
  if (!std::isfinite(value) || value < 0.0) {
    std::ostringstream message;
    message << "SkillMetrics: " << what << " must be a non-negative number, got " << value;
    throw ArgumentError(message.str());
  }
}

}  // namespace

SkillMetrics::SkillMetrics(VolumeData& volume, MetricsConfig config)
    : volume_(volume),
      config_(std::move(config)),
      in_target_(65536, false),
      distances_(std::make_unique<StructureDistances>(volume)) {
  check_non_negative(config_.excess_force, "excess_force");
  check_non_negative(config_.stroke_gap, "stroke_gap");
  check_non_negative(config_.turn_angle, "turn_angle");
  check_non_negative(config_.field_band, "field_band");
  if (!(config_.turn_step > 0.0)) {
    throw ArgumentError("SkillMetrics: turn_step must be a positive number of metres");
  }
  for (std::uint16_t id : config_.target_labels) in_target_[id] = true;
  const auto& shape = volume_.shape();
  if (!config_.target_mask.empty() &&
      config_.target_mask.size() != static_cast<std::size_t>(shape[0]) * shape[1] * shape[2]) {
    throw ArgumentError("SkillMetrics: target_mask has " +
                        std::to_string(config_.target_mask.size()) + " voxels, the volume " +
                        std::to_string(static_cast<std::size_t>(shape[0]) * shape[1] * shape[2]));
  }
  std::set<std::string> names;
  for (const ProtectedStructure& s : config_.protect) {
    if (!names.insert(s.name).second) {
      throw ArgumentError("SkillMetrics: two protected structures are named '" + s.name + "'");
    }
    if (s.labels.empty()) {
      throw ArgumentError("SkillMetrics: protected structure '" + s.name + "' names no label");
    }
    check_non_negative(s.margin, "the margin of '" + s.name + "'");
    Watch w;
    w.band = s.margin + config_.field_band;
    if (!(w.band > 0.0) || !std::isfinite(w.band)) {
      throw ArgumentError("SkillMetrics: the field of '" + s.name +
                          "' needs a positive margin + field_band");
    }
    w.key = distances_->track_labels(s.labels, w.band);
    w.metrics.name = s.name;
    w.metrics.margin = s.margin;
    w.metrics.closest = std::numeric_limits<double>::infinity();
    watches_.push_back(std::move(w));
  }
  const Eigen::Vector3d v = volume_.voxel_size();
  sum_.voxel_volume = v.x() * v.y() * v.z();
}

std::int64_t SkillMetrics::field_waits() const {
  return distances_ == nullptr ? 0 : distances_->waits();
}

double SkillMetrics::field_wait_seconds() const {
  return distances_ == nullptr ? 0.0 : distances_->wait_seconds();
}

double SkillMetrics::clearance(std::size_t s, const Eigen::Vector3d& p, double r) const {
  const Watch& w = watches_.at(s);
  return std::min(distances_->distance(w.key, p), w.band) - r;
}

void SkillMetrics::close(OpenStroke& open, std::vector<Stroke>& strokes) {
  if (!open.open) return;
  Stroke s = open.stroke;
  const double chord = (open.last - open.start).norm();
  s.straightness = s.length > 0.0 ? std::min(1.0, chord / s.length) : 1.0;
  strokes.push_back(s);
  open.open = false;
}

void SkillMetrics::add(const ToolTick& tick) {
  if (tick.removed.size() != tick.removed_labels.size()) {
    throw ArgumentError("SkillMetrics: a tick's removed voxels and their labels differ in count");
  }
  for (int s : tick.take_fields) {
    if (s < 0 || static_cast<std::size_t>(s) >= watches_.size()) {
      throw ArgumentError("SkillMetrics: step " + std::to_string(tick.step) +
                          " takes the field of protected structure " + std::to_string(s) +
                          ", but there are " + std::to_string(watches_.size()));
    }
  }
  if (config_.apply_removals && !tick.removed.empty()) {
    const std::vector<std::uint16_t> had = volume_.remove_voxels(tick.removed, "replay");
    for (std::size_t r = 0; r < had.size(); ++r) {
      if (had[r] == tick.removed_labels[r] || tick.removed_labels[r] == 0) continue;
      const auto& v = tick.removed[r];
      std::ostringstream message;
      message << "SkillMetrics: step " << tick.step << " removed voxel (" << v[0] << ", " << v[1]
              << ", " << v[2] << ") with label " << tick.removed_labels[r]
              << ", but the volume holds " << had[r]
              << " there: the recording was made on another anatomy";
      throw StateError(message.str());
    }
  }
  ++sum_.ticks;
  sum_.total_time += tick.dt;
  if (tick.burr_on) sum_.burr_on_time += tick.dt;
  const bool cutting = !tick.removed.empty();
  const double force = tick.force.norm();

  // Removed voxels by label and by region.
  const auto& shape = volume_.shape();
  for (std::size_t r = 0; r < tick.removed_labels.size(); ++r) {
    const std::uint16_t label = tick.removed_labels[r];
    if (label == 0) continue;
    if (sum_.removed_by_label.size() <= label) sum_.removed_by_label.resize(label + 1, 0);
    ++sum_.removed_by_label[label];
    bool inside = in_target_[label];
    if (!config_.target_mask.empty()) {
      const auto& v = tick.removed[r];
      for (int a = 0; a < 3; ++a) {
        if (v[a] < 0 || v[a] >= shape[a]) {
          throw OutOfRange("SkillMetrics: removed voxel (" + std::to_string(v[0]) + ", " +
                           std::to_string(v[1]) + ", " + std::to_string(v[2]) +
                           ") is outside the volume");
        }
      }
      inside = config_.target_mask[volume_.linear_index(v[0], v[1], v[2])] != 0;
    }
    ++(inside ? sum_.removed_in_target : sum_.removed_outside_target);
  }

  // The fields follow the structures' own edits: told this tick's removed voxels (every edit of
  // the volume since the last tick), they start local updates, taken kFollowTicks later.
  // Replayed from a real-time session, they are taken at the ticks that session took them.
  fields_taken_.clear();
  if (!watches_.empty()) {
    distances_->removed(-1, tick.removed, tick.removed_labels);
    if (tick.scheduled) {
      std::vector<int> keys;
      for (int s : tick.take_fields) keys.push_back(watches_[static_cast<std::size_t>(s)].key);
      distances_->tick_taking(keys);
    } else {
      distances_->tick(!realtime_);
    }
    for (int key : distances_->taken()) {
      for (std::size_t s = 0; s < watches_.size(); ++s) {
        if (watches_[s].key == key) fields_taken_.push_back(static_cast<int>(s));
      }
    }
  }
  for (std::size_t s = 0; s < watches_.size(); ++s) {
    Watch& w = watches_[s];
    const auto& labels = config_.protect[s].labels;
    std::int64_t breached = 0;
    for (std::uint16_t label : tick.removed_labels) {
      breached += std::find(labels.begin(), labels.end(), label) != labels.end();
    }
    if (breached > 0) {
      if (w.metrics.first_breach_step < 0) {
        w.metrics.first_breach_step = tick.step;
        w.metrics.first_breach_time = tick.time;
      }
      w.metrics.voxels_removed += breached;
    }
    const double c = clearance(s, tick.tip, tick.burr_radius);
    if (c < w.metrics.closest) {
      w.metrics.closest = c;
      w.metrics.closest_step = tick.step;
      w.metrics.closest_time = tick.time;
    }
    const bool inside = c < w.metrics.margin;
    if (inside) {
      if (!w.inside) ++w.metrics.contacts;
      w.metrics.time_in_margin += tick.dt;
      w.force_sum += force;
      ++w.force_ticks;
      w.metrics.force_in_margin_max = std::max(w.metrics.force_in_margin_max, force);
      w.metrics.burr_diameter_in_margin =
          std::max(w.metrics.burr_diameter_in_margin, 2.0 * tick.burr_radius);
    }
    w.inside = inside;
  }

  if (cutting) {
    sum_.cutting_time += tick.dt;
    cutting_forces_.push_back(static_cast<float>(force));
    cutting_force_sum_ += force;
    sum_.cutting_force_max = std::max(sum_.cutting_force_max, force);
    if (force > config_.excess_force) sum_.time_above_excess_force += tick.dt;
  }

  // Strokes: cutting ticks no more than stroke_gap apart.
  OpenStroke& o = stroke_;
  if (o.open && !cutting && tick.time - o.last_cut_time > config_.stroke_gap) {
    close(o, sum_.strokes);
  }
  if (cutting) {
    if (!o.open) {
      o = OpenStroke{};
      o.open = true;
      o.stroke.first_step = tick.step;
      o.stroke.duration = tick.dt;
      o.start = o.last = o.sample = tick.tip;
    } else {
      o.stroke.length += (tick.tip - o.last).norm();
      o.stroke.duration += tick.time - o.last_cut_time;
      o.last = tick.tip;
      const Eigen::Vector3d step = tick.tip - o.sample;
      if (step.norm() >= config_.turn_step) {
        const Eigen::Vector3d heading = step.normalized();
        if (o.heading.squaredNorm() > 0.0 &&
            std::acos(std::clamp(heading.dot(o.heading), -1.0, 1.0)) > config_.turn_angle) {
          ++o.stroke.direction_changes;
        }
        o.heading = heading;
        o.sample = tick.tip;
      }
    }
    o.stroke.last_step = tick.step;
    o.stroke.voxels += static_cast<std::int64_t>(tick.removed.size());
    o.last_cut_time = tick.time;
  }
}

MetricsSummary SkillMetrics::summary() const {
  MetricsSummary out = sum_;
  OpenStroke open = stroke_;
  close(open, out.strokes);
  if (!cutting_forces_.empty()) {
    out.cutting_force_mean = cutting_force_sum_ / cutting_forces_.size();
    std::vector<float> f = cutting_forces_;
    // The nearest-rank 95th percentile.
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * f.size())) - 1;
    std::nth_element(f.begin(), f.begin() + rank, f.end());
    out.cutting_force_p95 = f[rank];
  }
  if (out.cutting_time > 0.0) {
    out.efficiency = out.removed_in_target * out.voxel_volume / (out.cutting_time / 60.0);
  }
  for (const Watch& w : watches_) {
    StructureMetrics m = w.metrics;
    if (w.force_ticks) m.force_in_margin_mean = w.force_sum / w.force_ticks;
    out.structures.push_back(m);
  }
  return out;
}

Eigen::Vector3d burr_in_volume(const Eigen::Matrix4d& world_from_volume,
                               const Eigen::Vector3d& burr_in_world) {
  const Eigen::Isometry3d volume(world_from_volume);
  return volume.inverse() * burr_in_world;
}

}  // namespace ambfplus
