#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class RigidBody;
class SoftBody;

/// One ray of a proximity sensor, in the sensor frame: it runs from `offset` to
/// `offset + direction * range`, the direction taken as given (not normalised), as AMBF does.
struct AMBFPLUS_API SensorRay {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();      ///< `array[i].offset`
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< `array[i].direction`
};

/// AMBF's `parametric` ray fan in the sensor frame: resolution x resolution rays about +x, spread
/// over `horizontal angle` (about z) and `vertical angle` (about y), each starting `start offset`
/// out along its own direction; ray (i, j) is element resolution * i + j (i horizontal).
/// Throws ArgumentError for a resolution below 2.
AMBFPLUS_API std::vector<SensorRay> parametric_sensor_rays(int resolution, double horizontal_angle,
                                                           double vertical_angle,
                                                           double start_offset);

/// Everything needed to create a proximity (ray-cast) sensor: AMBF's `type: Proximity` block.
struct AMBFPLUS_API ProximitySensorSpec {
  std::string name;             ///< `name`
  RigidBody* parent = nullptr;  ///< `parent`: the body it is fixed to (required)
  /// `location` {position, orientation}: the sensor frame in the parent body's frame.
  Eigen::Matrix4d location = Eigen::Matrix4d::Identity();
  double range = 0.5;  ///< `range`, m: how far each ray reaches (per unit direction); AMBF 0.5
  /// `array` ({offset, direction} each), or the rays of `parametric` (parametric_sensor_rays).
  std::vector<SensorRay> rays;
  bool visible = false;        ///< `visible`; AMBF false (not drawn yet)
  double visible_size = 0.02;  ///< `visible size`, m; AMBF 0.02

  /// Throws ArgumentError naming the sensor and the value unless every value can be used (a
  /// rigid location, range > 0, at least one ray, each with a finite offset and a finite,
  /// non-zero direction); its parent is the constructor's to check.
  void validate() const;
};

/// AMBF's `parametric` block as a mapping: resolution (2), horizontal angle, vertical angle,
/// start offset (0 each; spaces or underscores), turned into its rays.
AMBFPLUS_API std::vector<SensorRay> parametric_sensor_rays(const OptionMap& parametric);

/// add_sensor's keyword options: location (4x4 in the parent's frame) or pose (4x4 world, now;
/// the parent must be set first), range, one ray by offset and direction, or rays ([{offset,
/// direction}] or [(offset, direction)]) or parametric, visible, visible_size.
AMBFPLUS_API const OptionTable<ProximitySensorSpec>& proximity_sensor_options();

/// What one ray saw at the last update.
struct AMBFPLUS_API SensorHit {
  bool triggered = false;  ///< something was within the ray's reach
  /// Metres from the ray's start to the hit; the ray's length when nothing was hit (a range
  /// finder's "nothing closer than its range").
  double distance = 0.0;
  /// distance / ray length (AMBF's depth fraction), 1 when nothing was hit.
  double fraction = 1.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< world frame; the ray's end on a miss
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, world frame; zero on a miss
  RigidBody* body = nullptr;                         ///< the rigid body hit, if it was one
  SoftBody* soft_body = nullptr;                     ///< the soft body hit, if it was one
  int soft_body_node = -1;  ///< the hit soft body's node nearest the hit point
};

/// A set of rays fixed to a rigid body that report the nearest body along each, updated at every
/// world step after physics (AMBF's proximity sensor). Rays do not see the parent body, nor
/// bodies without collision.
class AMBFPLUS_API ProximitySensor : public Object {
 public:
  ~ProximitySensor() override;
  ObjectKind kind() const override { return ObjectKind::kSensor; }
  const ProximitySensorSpec& spec() const { return spec_; }
  RigidBody& parent() const { return *spec_.parent; }
  double range() const { return spec_.range; }
  void set_range(double range);
  std::size_t ray_count() const { return spec_.rays.size(); }

  /// Each ray's result at the last update (world step, or update()).
  const std::vector<SensorHit>& hits() const { return hits_; }
  /// Whether any ray is triggered.
  bool triggered() const;
  /// Where ray i starts and ends now, world frame.
  Eigen::Vector3d ray_start(int ray) const;
  Eigen::Vector3d ray_end(int ray) const;

  /// Places the sensor (its location on the parent follows, so it moves with the parent).
  void set_pose(const Eigen::Isometry3d& pose) override;
  /// Follows the parent and casts every ray now (the world does this after each physics step).
  void update();

 private:
  friend class Model;
  ProximitySensor(Model& model, const ProximitySensorSpec& spec, int id);
  void check_ray(int ray) const;

  ProximitySensorSpec spec_;
  std::vector<SensorHit> hits_;
};

}  // namespace ambfplus
