#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "render/gl_program.h"

namespace ambfplus {
class World;
}

namespace ambfplus::render {

/// The world's lights in a camera's frame, grouped by type as lighting.glsl wants them. A world
/// without lights gets a headlight shining along the camera's view.
struct LightSet {
  LightSet(const World& world, const Eigen::Isometry3d& camera_from_world);

  /// The shader defines of this light-count combination (one program variant each).
  std::string defines() const;
  /// Sets the light uniforms of a program in use.
  void upload(Program& program) const;

  std::vector<float> dir_direction, dir_color;
  std::vector<float> point_position, point_color, point_attenuation;
  std::vector<float> spot_position, spot_direction, spot_color, spot_attenuation, spot_cos_cutoff,
      spot_exponent;
  int directional = 0, point = 0, spot = 0;
};

}  // namespace ambfplus::render
