#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/haptics/fixture.h"
#include "ambfplus/haptics/mesh_collider.h"
#include "ambfplus/haptics/proxy.h"
#include "ambfplus/haptics/voxel_collider.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class StructureDistances;
class RigidBody;
class Volume;

/// How the burr removes tissue.
enum class RemovalMode {
  /// Volume per second = cutting_rate x speed x normal force / label hardness, independent of
  /// the step and the voxel size (whole voxels, the remainder carried to the next step).
  kPhysical,
  /// The original's rule: a fixed number of voxels per step for each burr (1, 3, 6, 10).
  kCompatible,
};
/// Parses "physical" and "compatible" (any case).
AMBFPLUS_API RemovalMode parse_removal_mode(const std::string& name);
AMBFPLUS_API const char* removal_mode_name(RemovalMode mode);

/// Everything needed to create a drill.
struct AMBFPLUS_API DrillSpec {
  std::string name;
  Volume* volume = nullptr;                                        ///< the anatomy it drills
  std::vector<double> burr_diameters{0.001, 0.002, 0.004, 0.006};  ///< metres
  int burr = 3;                                                    ///< index into burr_diameters
  int cursors = 8;                                                 ///< tip + shaft cursors, 1..16
  double spacing = 0.0015;          ///< metres between cursors along the shaft
  std::vector<double> shaft_radii;  ///< metres; empty: 0.65 mm, 0.75 mm, ... (as the original)
  double stiffness = 700.0;         ///< N/m of proxy-goal separation
  double damping = 0.0;             ///< N s/m against the goal's velocity while in contact
  double max_force = 10.0;          ///< N
  double soft_start = 0.0;          ///< s over which forces ramp up after the drill is made
  Friction friction;
  RemovalMode removal = RemovalMode::kPhysical;
  double cutting_rate = 30e-9;                    ///< m^3 / (s N) at full speed (physical mode)
  std::vector<int> voxels_per_step{1, 3, 6, 10};  ///< per burr (compatible mode)
  /// Initial goal: world from drill, the burr's centre at the origin and the shaft along +x.
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  /// Forbidden-region fixtures, one per structure (Drill::set_fixtures).
  std::vector<FixtureSpec> fixtures;

  /// Throws ArgumentError naming the drill and the value unless every value can be used (burrs
  /// > 0 with a valid index, 1..16 cursors with spacing > 0 and one shaft radius each when
  /// given, one voxel count per burr, forces, rates and friction finite and in range, a rigid
  /// pose); its volume is the constructor's to check.
  void validate() const;
};

/// add_drill's keyword options (a DRILL block's keys, spaces for underscores): burr_diameters,
/// burr, cursors, spacing (cursor spacing), shaft_radii, stiffness, damping, max_force,
/// soft_start, static_friction, dynamic_friction, friction ({static, dynamic}), removal,
/// cutting_rate, voxels_per_step, pose, fixtures (a list of fixture_options() mappings).
AMBFPLUS_API const OptionTable<DrillSpec>& drill_options();

/// A fixture from a mapping of fixture_options() keys (structure and start required); errors
/// name `key` (e.g. "fixtures[1]").
AMBFPLUS_API FixtureSpec fixture_from(const OptionValue& value, const std::string& key);

/// One voxel taken by the burr.
struct AMBFPLUS_API RemovedVoxel {
  std::int64_t step = 0;
  std::array<int, 3> voxel{0, 0, 0};
  std::uint16_t label = 0;
};

/// Something a training session should react to.
struct AMBFPLUS_API DrillEvent {
  std::int64_t step = 0;
  std::string kind;  ///< "critical": a voxel of a critical label was removed
  std::uint16_t label = 0;
  std::array<int, 3> voxel{0, 0, 0};
};

/// A target pose for the drill at a time, reached by linear interpolation.
struct AMBFPLUS_API DrillWaypoint {
  double time = 0.0;  ///< seconds from when the waypoints are set
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  bool on = false;
  double speed = 1.0;
};

class Drill;
/// Creates a drill in a model, working on a volume of the same world. Throws ArgumentError for a
/// bad spec or a taken name.
AMBFPLUS_API Drill& add_drill(Model& model, const DrillSpec& spec);

/// The paper's drill: a tip cursor of the burr's radius and shaft cursors along the axis, each
/// a finger proxy against the volume. The cursor with the largest proxy-goal error drives the
/// drill's pose and the force fed back; only the tip removes tissue, and only when it leads, the
/// drill is on and it touches the volume. It cuts the voxels it touches (centres within 0.6 voxel
/// of the burr's surface), those nearest the goal first. The world's other rigid bodies (all but
/// those attached to the drill) stop the cursors at their triangles, where they are at each tick.
/// Stepped with its world; deterministic.
class AMBFPLUS_API Drill : public Object {
 public:
  ~Drill() override;
  ObjectKind kind() const override { return ObjectKind::kDrill; }
  Volume& volume() const { return *volume_; }
  const DrillSpec& spec() const { return spec_; }

  // --- Commands
  /// Places the drill at pose at once, as at its creation: goal, cursors and pose (a set_goal
  /// moves it there through the proxies, stopping at tissue; this does not).
  void place(const Eigen::Isometry3d& pose);
  /// Where the device puts the drill (world from drill).
  void set_goal(const Eigen::Isometry3d& goal);
  const Eigen::Isometry3d& goal() const { return goal_; }
  void set_on(bool on) { on_ = on; }
  bool on() const { return on_; }
  /// Burr speed, 0..1 of full speed.
  void set_speed(double speed);
  double speed() const { return speed_; }
  /// Selects burr i of spec().burr_diameters.
  void set_burr(int index);
  int burr() const { return burr_; }
  double burr_radius() const { return spec_.burr_diameters[burr_] / 2; }
  void set_removal_mode(RemovalMode mode) { spec_.removal = mode; }
  void set_stiffness(double k);
  void set_cutting_rate(double rate);
  /// Cutting energy of a label relative to bone (1): the physical rate divides by it.
  void set_hardness(std::uint16_t label, double hardness);
  /// Follows these from now on, then holds the last one; an empty list stops following.
  void set_waypoints(const std::vector<DrillWaypoint>& waypoints);
  /// Bodies that move with the drill (its meshes), at a fixed offset from the drill frame; they
  /// become kinematic.
  void attach(RigidBody& body, const Eigen::Isometry3d& offset = Eigen::Isometry3d::Identity());
  /// Whether attached bodies show the goal (where the hand is) instead of the drill's pose
  /// (where the leading cursor's proxy holds it, the default).
  void set_meshes_follow_goal(bool on) { meshes_follow_goal_ = on; }
  bool meshes_follow_goal() const { return meshes_follow_goal_; }
  /// Compatible removal: voxels a step removes with burr i.
  void set_voxels_per_step(int burr, int count);

  /// One haptic step: cursors, force, removal. Called by World::step.
  void tick(double dt, std::int64_t step);
  /// Whether a real-time loop steps it (the drills system says so before each tick): a tick
  /// then never waits for a structure's rebuilt distance field, taking it once it is ready.
  void set_realtime(bool on) { realtime_ = on; }
  bool realtime() const { return realtime_; }
  /// The world's rigid bodies changed (one was added or is about to be removed): the cursors'
  /// mesh collider is rebuilt at the next tick (the drills system calls it).
  void bodies_changed() { meshes_stale_ = true; }

  // --- State after the last tick (world frame)
  /// The force fed back to the device: the leading cursor's, N.
  const Eigen::Vector3d& force() const { return force_; }
  /// The sum over all cursors, N.
  const Eigen::Vector3d& total_force() const { return total_force_; }
  int cursor_count() const { return static_cast<int>(cursors_.size()); }
  int leading_cursor() const { return leading_; }
  Eigen::Vector3d cursor_proxy(int i) const;
  Eigen::Vector3d cursor_goal(int i) const;
  double cursor_radius(int i) const { return cursors_[i].radius(); }
  int cursor_contacts(int i) const { return cursors_[i].contacts(); }
  /// Surface normal at the tip's first contact (world), zero without contact.
  Eigen::Vector3d tip_normal() const;
  /// Distance from the burr's surface to each critical label of the volume (metres, 0 when
  /// touching, infinity when none is left), in label order. It comes from each structure's
  /// distance field, which follows the drilling: the distance from the burr's centre (its tip
  /// cursor's proxy) to the nearest voxel centre of the structure, less the burr's radius and
  /// half a voxel. Exact within kExactReach of the burr's surface; beyond, a lower bound (the
  /// distance to the box around the structure, at least kExactReach). A field is rebuilt on
  /// another thread after a cut into its structure and taken into use 50 ticks later (the same
  /// tick in every run); until then it answers for the structure before the cut, a lower bound.
  /// The volume's critical labels, in the order critical_distances() and the step log's
  /// `critical_distance` column give them (fixed when the drill is made).
  const std::vector<std::uint16_t>& critical_labels() const { return critical_labels_; }
  const std::vector<std::pair<std::uint16_t, double>>& critical_distances() const {
    return critical_distances_;
  }
  /// How far from the burr's surface (metres) distances to structures are exact.
  static constexpr double kExactReach = 0.005;

  // --- Virtual fixtures (forbidden regions around structures)
  /// Sets the fixture of a structure, replacing the one it had: the structure is resolved by
  /// label name or id (NotFound names the labels), the spec checked (ArgumentError), and the
  /// structure's distance field built or widened as the fixture needs.
  void set_fixture(const FixtureSpec& fixture);
  /// Replaces every fixture, all checked before any is set; an empty list removes them all.
  void set_fixtures(const std::vector<FixtureSpec>& fixtures);
  /// The fixtures in the order set, structures by label name.
  std::vector<FixtureSpec> fixtures() const;
  /// The force the fixtures added to force() at the last tick (N, world frame): the regions'
  /// push, the hard stops' spring, and the passivity damping.
  const Eigen::Vector3d& fixture_force() const { return fixture_force_; }
  /// Whether the fixtures' force is kept passive (on by default): an energy observer sums the
  /// work the held force does on the hand (the goal) each tick, and when the fixtures would give
  /// back more energy than they took (a sampled stiff region does, at 1 kHz), a damping against
  /// the hand's velocity dissipates the excess (Hannaford and Ryu's passivity controller).
  void set_fixture_passivity(bool on) { fixture_passivity_ = on; }
  bool fixture_passivity() const { return fixture_passivity_; }
  // --- Guidance: stay in the plan
  /// Keeps the burr in a planned region: a fixture (the start, max_force, stop and enabled of
  /// `fixture`; its structure is ignored) whose forbidden side is every labelled voxel outside
  /// the region, so that with a stop nothing outside it is cut. `mask` holds one entry per
  /// voxel, i fastest, non-zero in the plan. Throws ArgumentError for a mask of another size or
  /// a bad spec.
  void set_plan(const std::vector<std::uint8_t>& mask, const FixtureSpec& fixture);
  /// The same with the plan given as the voxels of some labels (names or ids).
  void set_plan(const std::vector<std::string>& labels, const FixtureSpec& fixture);
  void clear_plan();
  /// Turns the plan's fixture off or back on (its field kept: no rebuild). Throws ArgumentError
  /// without a plan.
  void set_plan_enabled(bool enabled);
  /// The plan's fixture (its structure "plan"), or nullptr without a plan.
  const FixtureSpec* plan() const { return plan_ ? &plan_->spec : nullptr; }
  /// Voxels in the plan.
  std::int64_t plan_voxels() const { return plan_voxels_; }
  // --- Guidance: follow the plan
  /// Draws the burr toward the nearest voxel of the plan not yet removed (any labelled voxel in
  /// the planned region): a force along the direction to it of max_force x min(1, d / start) for
  /// a burr surface d metres away, falling back to zero over the next `start` beyond 2 x start
  /// (so it never jumps), and none once the burr touches the target. It follows the drilling as
  /// the critical structures' fields do, joins the fixtures' force (kept passive likewise) and
  /// needs a plan (set_plan; ArgumentError without one). `enabled` false keeps the settings off.
  void follow_plan(double max_force, double start, bool enabled = true);
  /// Whether the burr is drawn toward the plan, and with what (max_force N, start m).
  bool follows_plan() const { return follow_.enabled; }
  double follow_max_force() const { return follow_.max_force; }
  double follow_start() const { return follow_.start; }

  /// The regions' push on the burr centred at p (volume frame; N, volume axes): the sum of
  /// max_force x (1 - d / start) away from each structure nearer than its start, without the
  /// hard stops' spring or the damping (what each tick evaluates at the burr's proxy).
  Eigen::Vector3d fixture_push(const Eigen::Vector3d& p) const;
  /// Distance (metres) from the burr's surface to a structure with a fixture or a critical
  /// label, with the burr centred at p (volume frame); negative when it overlaps.
  double structure_distance(std::uint16_t label, const Eigen::Vector3d& p) const;
  /// Voxels removed so far and not yet taken; take_* hands them over. Bounded: the newest
  /// kMaxRemoved voxels and kMaxEvents events are kept, older ones dropped and counted. Every
  /// step appends to them: read removed() and events() under the world's lock while a
  /// real-time loop steps; take_removed() and take_events() take the lock themselves.
  const std::deque<RemovedVoxel>& removed() const { return removed_; }
  std::deque<RemovedVoxel> take_removed();
  const std::deque<DrillEvent>& events() const { return events_; }
  std::deque<DrillEvent> take_events();
  static constexpr std::size_t kMaxRemoved = 262144;  ///< about 6 MB
  static constexpr std::size_t kMaxEvents = 65536;
  /// Removed voxels and events dropped because nobody took them in time.
  std::int64_t removed_dropped() const { return removed_dropped_; }
  std::int64_t events_dropped() const { return events_dropped_; }
  /// Ticks whose timings are kept.
  static constexpr std::size_t kTickHistory = 16384;
  /// Wall time of the last ticks, seconds (up to kTickHistory).
  const std::deque<double>& tick_seconds() const { return tick_seconds_; }
  /// CPU time of the thread for the same ticks: what the tick costs, whatever else the machine
  /// is doing.
  const std::deque<double>& tick_cpu_seconds() const { return tick_cpu_seconds_; }
  const VoxelCollider& collider() const { return *collider_; }
  /// The rigid bodies the cursors collide with (volume frame), as of the last tick.
  const MeshCollider& mesh_collider() const { return meshes_; }

 private:
  friend Drill& add_drill(Model& model, const DrillSpec& spec);
  Drill(Model& model, const DrillSpec& spec, int id);
  void follow_waypoints();
  // Brings the mesh collider up to date with the world's bodies and their poses.
  void sync_meshes();
  // The parts of a tick, in order.
  void update_cursors();
  void place_drill();
  /// The cursors' forces; returns the tip's, in the volume frame.
  Eigen::Vector3d update_forces(double dt);
  /// The voxels the burr touches, (squared distance to the goal, voxel), nearest first.
  std::vector<std::pair<double, std::array<int, 3>>> cuttable_voxels() const;
  void remove_tissue(double dt, std::int64_t step, const Eigen::Vector3d& tip_force_volume);
  void update_critical_distances();
  /// The burr surface's distance to a tracked structure with its centre at p, and the
  /// direction away from it (unit, or zero where the field gives none).
  double surface_distance(int label, const Eigen::Vector3d& p, Eigen::Vector3d* away) const;
  /// Where the tip's goal may go (volume frame): from where it was held toward `goal`, stopped
  /// and slid along the surface of every hard stop.
  Eigen::Vector3d held_tip_goal(const Eigen::Vector3d& goal);
  /// The smallest clearance (metres) of a burr centred at p from the hard stops, and the
  /// direction away from the nearest; infinity without stops.
  double stop_clearance(const Eigen::Vector3d& p, Eigen::Vector3d* away) const;
  /// The fixtures' force at this tick (world frame), passivity control included.
  Eigen::Vector3d update_fixture_force(double dt, const Eigen::Vector3d& goal_velocity);
  void fixtures_changed();
  void log_removed(const RemovedVoxel& voxel);
  void log_event(const DrillEvent& event);
  void record_timing(double wall, double cpu);

  Volume* volume_;
  DrillSpec spec_;
  std::unique_ptr<VoxelCollider> collider_;
  std::unique_ptr<StructureDistances> structures_;
  std::vector<std::uint16_t> critical_labels_;
  double half_voxel_ = 0.0;  // added to the burr's radius: distances are to voxel faces
  double field_band_ = 0.0;  // the band of the critical labels' fields
  struct ActiveFixture {
    FixtureSpec spec;
    std::uint16_t label;
  };
  struct Follow {
    bool enabled = false;
    double max_force = 0.0;
    double start = 0.0;
  };
  Follow follow_;  // follow the plan (label kPlanTarget of the structures' fields)
  std::vector<ActiveFixture> fixtures_;
  std::optional<ActiveFixture> plan_;  // label 0: the tissue outside the plan
  std::shared_ptr<const std::vector<std::uint8_t>> plan_mask_;
  std::int64_t plan_voxels_ = 0;
  bool plan_stop_ = false;                    // nothing outside the plan is cut
  std::vector<const ActiveFixture*> active_;  // the enabled fixtures and plan
  std::vector<bool> uncuttable_;              // by label: a structure with an enabled hard stop
  bool any_stop_ = false;
  Eigen::Vector3d held_goal_ = Eigen::Vector3d::Zero();  // the tip's held goal, volume frame
  bool held_valid_ = false;
  Eigen::Vector3d fixture_force_ = Eigen::Vector3d::Zero();
  double fixture_energy_ = 0.0;  // J the fixtures took from the hand (passivity observer)
  bool fixture_passivity_ = true;
  std::vector<ProxyCursor> cursors_;
  Eigen::Isometry3d goal_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d last_goal_position_ = Eigen::Vector3d::Zero();
  bool on_ = false;
  double speed_ = 1.0;
  int burr_;
  int leading_ = 0;
  double budget_ = 0.0;  // m^3 of removal owed (physical mode)
  double age_ = 0.0;     // seconds since creation (soft start)
  Eigen::Vector3d force_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d total_force_ = Eigen::Vector3d::Zero();
  std::vector<double> hardness_;
  std::vector<std::pair<std::uint16_t, double>> critical_distances_;
  std::deque<RemovedVoxel> removed_;
  std::deque<DrillEvent> events_;
  std::int64_t removed_dropped_ = 0, events_dropped_ = 0;
  std::deque<double> tick_seconds_;
  std::deque<double> tick_cpu_seconds_;
  std::vector<std::pair<RigidBody*, Eigen::Isometry3d>> attached_;
  MeshCollider meshes_;
  std::vector<RigidBody*> mesh_bodies_;  // part i of meshes_ is mesh_bodies_[i]
  bool meshes_stale_ = true;             // meshes_ must be rebuilt from the world's bodies
  std::vector<DrillWaypoint> waypoints_;
  double waypoint_clock_ = 0.0;
  bool meshes_follow_goal_ = false;
  bool realtime_ = false;
};

}  // namespace ambfplus
