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

// Diffuse and specular light from direction to_light on a surface of colour base.
vec3 shade(vec3 base, vec3 n, vec3 to_eye, vec3 to_light, vec3 light_color) {
  float diffuse = max(dot(n, to_light), 0.0);
  float specular = 0.0;
  if (diffuse > 0.0) {
    specular = pow(max(dot(n, normalize(to_light + to_eye)), 0.0), u_shininess) * u_specular;
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
    rgb += shade(base, n, to_eye, -u_directional_direction[i], u_directional_color[i]);
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
    rgb += cone * attenuate(u_spot_attenuation[i], dist) *
           shade(base, n, to_eye, to_light, u_spot_color[i]);
  }
#endif
  return clamp(rgb, 0.0, 1.0);
}
