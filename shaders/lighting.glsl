// Blinn-Phong lighting shared by every surface shader (#include "lighting.glsl").
//
// The engine compiles one variant per light count of each type (the defines below), so every loop
// has a constant bound: a software rasteriser then runs only the code of the lights that exist.
// All positions and directions are in the camera frame; directions are unit vectors along which
// the light travels; colours are colour times intensity.

#ifndef DIRECTIONAL_LIGHTS
#define DIRECTIONAL_LIGHTS 1
#endif
#ifndef POINT_LIGHTS
#define POINT_LIGHTS 0
#endif
#ifndef SPOT_LIGHTS
#define SPOT_LIGHTS 0
#endif
#ifndef SHADOW_MAPS
#define SHADOW_MAPS 0
#endif
#define ARRAY_SIZE(n) ((n) > 0 ? (n) : 1)

uniform float u_specular;
uniform float u_shininess;
uniform float u_ambient;

uniform vec3 u_directional_direction[ARRAY_SIZE(DIRECTIONAL_LIGHTS)];
uniform vec3 u_directional_color[ARRAY_SIZE(DIRECTIONAL_LIGHTS)];
uniform vec3 u_point_position[ARRAY_SIZE(POINT_LIGHTS)];
uniform vec3 u_point_color[ARRAY_SIZE(POINT_LIGHTS)];
uniform vec3 u_point_attenuation[ARRAY_SIZE(POINT_LIGHTS)];
uniform vec3 u_spot_position[ARRAY_SIZE(SPOT_LIGHTS)];
uniform vec3 u_spot_direction[ARRAY_SIZE(SPOT_LIGHTS)];
uniform vec3 u_spot_color[ARRAY_SIZE(SPOT_LIGHTS)];
uniform vec3 u_spot_attenuation[ARRAY_SIZE(SPOT_LIGHTS)];
uniform float u_spot_cos_cutoff[ARRAY_SIZE(SPOT_LIGHTS)];
uniform float u_spot_exponent[ARRAY_SIZE(SPOT_LIGHTS)];

#if SHADOW_MAPS > 0
// Shadow maps of directional and spot lights (reversed depth: 1 nearest the light, compared
// GEQUAL, so 1 is lit). u_*_shadow[i] is light i's map, -1 for none.
uniform sampler2DShadow u_shadow_maps[SHADOW_MAPS];
uniform mat4 u_shadow_from_camera[SHADOW_MAPS];  // the light's clip space from the camera frame
uniform vec2 u_shadow_texel[SHADOW_MAPS];  // a texel's size at a point, x + y * clip w (metres)
uniform int u_directional_shadow[ARRAY_SIZE(DIRECTIONAL_LIGHTS)];
uniform int u_spot_shadow[ARRAY_SIZE(SPOT_LIGHTS)];

// How much of the light from map's light reaches p (0..1, bilinear percentage closer
// filtering). The point is moved off its surface by a texel and a half along the normal, so a
// surface does not shadow itself where the map's texels cut it at a slant.
float lit_fraction(int map, vec3 p, vec3 n, vec3 to_light) {
  if (map < 0) return 1.0;
  vec4 c = u_shadow_from_camera[map] * vec4(p, 1.0);
  float texel = u_shadow_texel[map].x + u_shadow_texel[map].y * c.w;
  float slant = sqrt(max(1.0 - dot(n, to_light) * dot(n, to_light), 0.0));
  c = u_shadow_from_camera[map] * vec4(p + n * (texel * (0.5 + 1.5 * slant)), 1.0);
  if (c.w <= 0.0) return 1.0;
  vec3 q = c.xyz / c.w;
  if (any(greaterThan(abs(q.xy), vec2(1.0)))) return 1.0;  // outside the map: nothing casts
  return texture(u_shadow_maps[map], vec3(q.xy * 0.5 + 0.5, q.z));
}
#define SHADOWED(map, p, n, to_light) lit_fraction(map, p, n, to_light)
#else
#define SHADOWED(map, p, n, to_light) 1.0
#endif

// Diffuse and specular light from direction to_light on a surface of colour base.
vec3 shade(vec3 base, vec3 n, vec3 to_eye, vec3 to_light, vec3 light_color) {
  float diffuse = max(dot(n, to_light), 0.0);
  float specular = 0.0;
  if (diffuse > 0.0) {
    float facing = max(dot(n, normalize(to_light + to_eye)), 0.0);
    specular = pow(facing, u_shininess) * u_specular;
#ifdef WET_SHININESS
    // A wet surface: a second, sharper and brighter lobe over the material's own.
    specular += pow(facing, WET_SHININESS) * u_specular * WET_GAIN;
#endif
  }
  return light_color * (diffuse * base + specular);
}

float attenuate(vec3 k, float dist) {
  return 1.0 / max(k.x + k.y * dist + k.z * dist * dist, 1e-6);
}

// The lit colour of a surface point p with unit normal n facing the viewer.
vec3 lit(vec3 base, vec3 n, vec3 p) {
  vec3 to_eye = normalize(-p);
  vec3 rgb = u_ambient * base;
#if DIRECTIONAL_LIGHTS > 0
  for (int i = 0; i < DIRECTIONAL_LIGHTS; ++i) {
    rgb += SHADOWED(u_directional_shadow[i], p, n, -u_directional_direction[i]) *
           shade(base, n, to_eye, -u_directional_direction[i], u_directional_color[i]);
  }
#endif
#if POINT_LIGHTS > 0
  for (int i = 0; i < POINT_LIGHTS; ++i) {
    vec3 d = u_point_position[i] - p;
    float dist = length(d);
    rgb += attenuate(u_point_attenuation[i], dist) *
           shade(base, n, to_eye, d / dist, u_point_color[i]);
  }
#endif
#if SPOT_LIGHTS > 0
  for (int i = 0; i < SPOT_LIGHTS; ++i) {
    vec3 d = u_spot_position[i] - p;
    float dist = length(d);
    vec3 to_light = d / dist;
    float c = dot(-to_light, u_spot_direction[i]);
    float cone = c < u_spot_cos_cutoff[i] ? 0.0 : pow(c, u_spot_exponent[i]);
    if (cone > 0.0) {
      rgb += cone * attenuate(u_spot_attenuation[i], dist) *
             SHADOWED(u_spot_shadow[i], p, n, to_light) *
             shade(base, n, to_eye, to_light, u_spot_color[i]);
    }
  }
#endif
  return clamp(rgb, 0.0, 1.0);
}
