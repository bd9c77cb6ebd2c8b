// CameraSpec, LightSpec and VolumeSpec: their checks and their keyword options.

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/light.h"
#include "ambfplus/scene/volume.h"
#include "util/strings.h"

namespace ambfplus {
namespace {

using V = const OptionValue&;
using K = const std::string&;

void require_non_negative(double value, const std::string& who, const char* what) {
  if (!(value >= 0) || !std::isfinite(value)) {
    throw ArgumentError(who + ": " + what + " must be finite and >= 0, got " +
                        std::to_string(value));
  }
}

// An RGB colour in 0..1.
std::array<float, 3> rgb(V v, K k) {
  if (!v.is_list() || v.list(k).size() != 3) throw ArgumentError(k + " must be (r, g, b)");
  const std::array<float, 4> c = v.rgba(k);
  return {c[0], c[1], c[2]};
}

void check_rgb(const std::array<float, 3>& c, const std::string& who, const char* what) {
  for (float x : c) {
    if (!(x >= 0 && x <= 1)) throw ArgumentError(who + ": " + what + " components must be in 0..1");
  }
}

}  // namespace

void CameraSpec::validate() const {
  const std::string who = "camera '" + name + "': ";
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw ArgumentError(who + "width and height must be in 1..16384, got " + std::to_string(width) +
                        "x" + std::to_string(height));
  }
  if (!(fov_y > 0.0 && fov_y < M_PI)) {
    throw ArgumentError(who + "fov_y must be in (0, pi) radians, got " + std::to_string(fov_y));
  }
  if (!(near > 0.0 && far > near && std::isfinite(far))) {
    throw ArgumentError(who + "clipping planes need 0 < near < far, got near " +
                        std::to_string(near) + ", far " + std::to_string(far));
  }
  check_rgb(background, "camera '" + name + "'", "background");
  check_antialiasing(name, antialiasing);
  if (publish.image_interval < 1 || publish.depth_interval < 1) {
    throw ArgumentError(who + "publish intervals must be >= 1");
  }
  checked_pose(pose, "camera '" + name + "'");
}

const OptionTable<CameraSpec>& camera_options() {
  using S = CameraSpec;
  using O = OptionTable<S>::Option;
  static const OptionTable<S> table(
      "add_camera()",
      {
          O{"width", "int", "pixels", [](S& s, V v, K k) { s.width = v.integer(k); }},
          O{"height", "int", "pixels", [](S& s, V v, K k) { s.height = v.integer(k); }},
          O{"fov_y", "float", "vertical field of view, rad",
            [](S& s, V v, K k) { s.fov_y = v.number(k); }},
          O{"near", "float", "m", [](S& s, V v, K k) { s.near = v.number(k); }},
          O{"far", "float", "m", [](S& s, V v, K k) { s.far = v.number(k); }},
          O{"pose", "numpy.ndarray", "4x4 world from camera (OpenCV frame)",
            [](S& s, V v, K k) { s.pose = v.matrix4(k); }},
          O{"background", "tuple[float, float, float]", "RGB in 0..1 where nothing is hit",
            [](S& s, V v, K k) { s.background = rgb(v, k); }},
          O{"shadows", "bool", "lights with a shadow_quality cast shadows in rgb",
            [](S& s, V v, K k) { s.shadows = v.boolean(k); }},
          O{"antialiasing", "int", "rgb antialiasing, 1 (off) to 4",
            [](S& s, V v, K k) { s.antialiasing = v.integer(k); }},
          O{"looks", "bool",
            "volumes in rgb get ambient occlusion, a bone texture and wet highlights",
            [](S& s, V v, K k) { s.looks = v.boolean(k); }},
      });
  return table;
}

LightSpec::Type parse_light_type(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "directional") return LightSpec::Type::kDirectional;
  if (n == "point") return LightSpec::Type::kPoint;
  if (n == "spot") return LightSpec::Type::kSpot;
  throw ArgumentError("unknown light type '" + name + "': expected directional, point or spot");
}

const char* light_type_name(LightSpec::Type type) {
  switch (type) {
    case LightSpec::Type::kDirectional:
      return "directional";
    case LightSpec::Type::kPoint:
      return "point";
    case LightSpec::Type::kSpot:
      return "spot";
  }
  return "?";
}

void LightSpec::validate() const {
  const std::string who = "light '" + name + "'";
  if (!(direction.norm() > 0.0) || !direction.allFinite() || !position.allFinite()) {
    throw ArgumentError(who + ": needs a finite position and a non-zero direction");
  }
  if (position.cwiseAbs().maxCoeff() > kMaxPosition) {
    throw ArgumentError(who +
                        ": position is beyond 1e+06 m of the origin, where nothing keeps "
                        "its precision");
  }
  check_rgb(color, who, "color");
  require_non_negative(intensity, who, "intensity");
  require_non_negative(spot_cutoff, who, "spot cutoff");
  require_non_negative(spot_exponent, who, "spot exponent");
  for (float a : attenuation) require_non_negative(a, who, "attenuation");
  if (shadow_quality < 0 || shadow_quality > kMaxShadowQuality) {
    throw ArgumentError(who + ": shadow_quality must be 0 (none) to " +
                        std::to_string(kMaxShadowQuality) + ", got " +
                        std::to_string(shadow_quality));
  }
}

const OptionTable<LightSpec>& light_options() {
  using S = LightSpec;
  using O = OptionTable<S>::Option;
  static const OptionTable<S> table(
      "add_light()",
      {
          O{"type", "LightType | str", "directional, point or spot",
            [](S& s, V v, K k) { s.type = parse_light_type(v.text(k)); }},
          O{"position", "tuple[float, float, float]", "world frame, m",
            [](S& s, V v, K k) { s.position = v.vector3(k); }},
          O{"direction", "tuple[float, float, float]", "world frame",
            [](S& s, V v, K k) { s.direction = v.vector3(k); }},
          O{"color", "tuple[float, float, float]", "RGB in 0..1",
            [](S& s, V v, K k) { s.color = rgb(v, k); }},
          O{"intensity", "float", "",
            [](S& s, V v, K k) { s.intensity = static_cast<float>(v.number(k)); }},
          O{"spot_cutoff", "float", "half-angle of a spot's cone, rad",
            [](S& s, V v, K k) { s.spot_cutoff = static_cast<float>(v.number(k)); }},
          O{"spot_exponent", "float", "falloff towards the cone's edge",
            [](S& s, V v, K k) { s.spot_exponent = static_cast<float>(v.number(k)); }},
          O{"attenuation", "tuple[float, float, float]", "constant, linear, quadratic",
            [](S& s, V v, K k) {
              const Eigen::Vector3d a = v.vector3(k);
              s.attenuation = {static_cast<float>(a[0]), static_cast<float>(a[1]),
                               static_cast<float>(a[2])};
            }},
          O{"shadow_quality", "int", "0 (no shadow) to 5: shadow maps of 256 to 4096 texels",
            [](S& s, V v, K k) { s.shadow_quality = v.integer(k); }},
      });
  return table;
}

void VolumeSpec::validate() const {
  const std::string who = "volume '" + name + "'";
  if (!data) throw ArgumentError(who + " needs volume data");
  if (!(iso > 0.0 && iso < 1.0)) {
    throw ArgumentError(who + ": iso must be in (0, 1), got " + std::to_string(iso));
  }
  require_non_negative(quality, who, "quality");
  require_non_negative(optical_density, who, "optical density");
  require_non_negative(specular, who, "specular");
  require_non_negative(shininess, who, "shininess");
  checked_pose(pose, who);
}

const OptionTable<VolumeSpec>& volume_options() {
  using S = VolumeSpec;
  using O = OptionTable<S>::Option;
  static const OptionTable<S> table(
      "add_volume()", {
                          O{"pose", "numpy.ndarray", "4x4 world from the volume frame",
                            [](S& s, V v, K k) { s.pose = v.matrix4(k); }},
                          O{"iso",
                            "float",
                            "iso level of the smoothed occupancy, (0, 1)",
                            [](S& s, V v, K k) { s.iso = v.number(k); },
                            {"iso-surface value"}},
                          O{"quality", "float", "AMBF's key, kept for files",
                            [](S& s, V v, K k) { s.quality = v.number(k); }},
                          O{"optical_density", "float", "AMBF's key, kept for files",
                            [](S& s, V v, K k) { s.optical_density = v.number(k); }},
                          O{"specular", "float", "Phong factor, 0..1",
                            [](S& s, V v, K k) { s.specular = static_cast<float>(v.number(k)); }},
                          O{"shininess", "float", "Phong exponent",
                            [](S& s, V v, K k) { s.shininess = static_cast<float>(v.number(k)); }},
                      });
  return table;
}

}  // namespace ambfplus
