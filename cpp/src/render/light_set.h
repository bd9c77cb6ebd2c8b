#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "render/gl_program.h"

namespace ambfplus {
class World;
}

namespace ambfplus::render {

/// The most lights whose shadows one camera draws (the first directional and spot lights with a
/// shadow quality above 0, in the world's order).
constexpr int kMaxShadowMaps = 4;
/// The texture unit of shadow map i is kShadowMapUnit + i (surface shaders use units 0..5).
constexpr int kShadowMapUnit = 8;

/// A light that casts shadows: what its shadow map is made of (world frame).
struct ShadowCaster {
  int light_id = 0;
  bool directional = true;  // else a spot light
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, along which the light travels
  double cutoff = 0.0;                                   // a spot's half-angle, radians
  int size = 0;                                          // texels a side
};

/// What surface shaders need of a camera's shadow maps (lighting.glsl's u_shadow_*).
struct ShadowUniforms {
  std::vector<GLuint> textures;    // per map, 0 where the light's map has nothing to cast
  std::vector<float> from_camera;  // per map, 16: the light's clip space from the camera frame
  std::vector<float> texel;        // per map, 2: a texel's size x + y * clip w, metres
  /// Binds the maps to units kShadowMapUnit + i and sets their uniforms.
  void upload(Program& program) const;
};

/// The world's lights in a camera's frame, grouped by type as lighting.glsl wants them. A world
/// without lights gets a headlight shining along the camera's view. With shadows, the lights of
/// a shadow quality above 0 (directional and spot, at most kMaxShadowMaps) are `casters`, and
/// dir_shadow and spot_shadow give each light's map index (-1 for none).
struct LightSet {
  LightSet(const World& world, const Eigen::Isometry3d& camera_from_world, bool shadows = false);

  /// The shader defines of this light-count combination (one program variant each).
  std::string defines() const;
  /// Sets the light uniforms of a program in use.
  void upload(Program& program) const;

  std::vector<float> dir_direction, dir_color;
  std::vector<float> point_position, point_color, point_attenuation;
  std::vector<float> spot_position, spot_direction, spot_color, spot_attenuation, spot_cos_cutoff,
      spot_exponent;
  int directional = 0, point = 0, spot = 0;
  std::vector<int> dir_shadow, spot_shadow;
  std::vector<ShadowCaster> casters;
};

}  // namespace ambfplus::render
