#pragma once

#include <array>
#include <string>

#include <Eigen/Core>

#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

/// The largest `shadow quality` (AMBF's scale: 0 none, 5 the largest maps).
constexpr int kMaxShadowQuality = 5;

/// Everything needed to create a light. A light shines along its +z axis.
struct AMBFPLUS_API LightSpec {
  enum class Type { kDirectional, kPoint, kSpot };
  std::string name;
  Type type = Type::kDirectional;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();
  std::array<float, 3> color{1.0f, 1.0f, 1.0f};
  float intensity = 1.0f;
  float spot_cutoff = 0.7f;    ///< half-angle of a spot light's cone, radians (AMBF's default)
  float spot_exponent = 0.7f;  ///< falloff towards the cone's edge (AMBF's default)
  std::array<float, 3> attenuation{1.0f, 0.0f, 0.0f};  ///< constant, linear, quadratic
  /// AMBF's `shadow quality`: 0 casts no shadow, 1..5 shadow maps of 256 to 4096 texels a side
  /// (directional and spot lights; cameras with shadows on draw them).
  int shadow_quality = 3;

  /// Throws ArgumentError naming the light and the value unless every value can be used (a
  /// finite position, a non-zero direction, colour in 0..1, intensity, cutoff and attenuation
  /// finite and >= 0).
  void validate() const;
};

/// Parses "directional", "point", "spot" (any case).
AMBFPLUS_API LightSpec::Type parse_light_type(const std::string& name);
AMBFPLUS_API const char* light_type_name(LightSpec::Type type);

/// add_light's keyword options: type, position, direction, color, intensity, spot_cutoff,
/// spot_exponent, attenuation, shadow_quality.
AMBFPLUS_API const OptionTable<LightSpec>& light_options();

/// A world holds at most this many lights of each type.
constexpr int kMaxLightsPerType = 8;

/// A light source. Worlds without lights are lit by a headlight at each camera.
class AMBFPLUS_API Light : public Object {
 public:
  ObjectKind kind() const override { return ObjectKind::kLight; }
  LightSpec::Type type() const { return type_; }
  const std::array<float, 3>& color() const { return color_; }
  float intensity() const { return intensity_; }
  float spot_cutoff() const { return spot_cutoff_; }
  float spot_exponent() const { return spot_exponent_; }
  const std::array<float, 3>& attenuation() const { return attenuation_; }
  /// 0 (no shadow) to 5; see LightSpec::shadow_quality. ArgumentError outside 0..5.
  int shadow_quality() const { return shadow_quality_; }
  void set_shadow_quality(int quality);
  /// The side of this light's shadow map in texels (256 << (quality - 1)); 0 for quality 0.
  int shadow_map_size() const { return shadow_quality_ > 0 ? 256 << (shadow_quality_ - 1) : 0; }
  /// Unit direction the light shines along, in the world frame (the pose's z axis).
  Eigen::Vector3d direction() const;

 private:
  friend class Model;
  Light(Model& model, const LightSpec& spec, int id);

  LightSpec::Type type_;
  std::array<float, 3> color_;
  float intensity_;
  float spot_cutoff_;
  float spot_exponent_;
  std::array<float, 3> attenuation_;
  int shadow_quality_;
};

}  // namespace ambfplus
