#version 450 core
// Ray casting of a segmented volume's iso-surface, in voxel units (voxel (i, j, k) spans
// [i, i+1) x [j, j+1) x [k, k+1), its centre at + 0.5).
//
// The surface is the iso level of the smoothed occupancy (trilinear). Rays skip bricks that
// cannot reach the level (a distance map at brick resolution says how far), march every half
// voxel inside the others, and refine a crossing by bisection. The label is that of the solid
// voxel with the largest trilinear weight at the hit (or, where the smoothed surface bridges a
// concave corner over eight empty voxels, the nearest solid voxel), the normal the field's
// negative gradient. VolumeData::raycast on the CPU is the same algorithm without the skipping.

#include "lighting.glsl"

#ifndef SHADE
#define SHADE 1
#endif

#ifndef NORMAL_SPAN
#define NORMAL_SPAN 1.2  // VolumeData::kNormalSpan
#endif
#ifndef EMPTY_SPACE_SKIPPING
#define EMPTY_SPACE_SKIPPING 1
#endif

in vec3 v_voxel;

uniform vec3 u_shape;
uniform vec3 u_eye;                // camera position, voxel units
#ifdef FROM_PIXELS
// Supersampling draws points over the pixels to sample: each fragment's ray goes through its
// own sub-pixel centre.
uniform mat4 u_voxel_from_clip;
uniform vec2 u_viewport;
#endif
#ifdef ORTHOGRAPHIC
uniform vec3 u_ray_dir;            // parallel rays (a directional light's shadow map), unit
uniform float u_ray_back;          // how far behind the box face rays start, voxels
#endif
uniform mat4 u_clip_from_voxel;
uniform mat4 u_camera_from_voxel;
uniform mat3 u_normal_from_voxel;  // camera-frame normals from voxel-unit gradients
uniform float u_level;             // iso level of the smoothed occupancy, 0..1
uniform sampler3D u_occupancy;     // smoothed occupancy, linear filtering, zero border
uniform usampler3D u_labels;       // label ids
uniform usampler3D u_bricks;       // Chebyshev distance, in bricks, to the nearest brick that
                                   // can reach the level (0 = this one can)
uniform sampler2D u_colors;        // label id -> colour, 256 per row
uniform int u_brick_size;

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out uint o_label;
layout(location = 3) out int o_instance;
layout(location = 4) out int o_voxel;
layout(location = 5) out vec4 o_segmentation;  // the label's colour (AMBF's voxel-colour mode)

uniform int u_instance;  // the volume's object id

vec3 inv_shape;
float field(vec3 u) { return texture(u_occupancy, u * inv_shape).r; }

// Distance along the ray to leave the box [lo, hi] it is inside.
float exit_distance(vec3 eye, vec3 inv_dir, vec3 lo, vec3 hi) {
  vec3 a = (lo - eye) * inv_dir;
  vec3 b = (hi - eye) * inv_dir;
  vec3 far_t = max(a, b);
  return min(min(far_t.x, far_t.y), far_t.z);
}

uint label_at(ivec3 v) {
  if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(u_shape)))) return 0u;
  return texelFetch(u_labels, v, 0).r;
}

// The solid voxel with the largest trilinear weight at u (its label; the voxel in `voxel`).
uint dominant_label(vec3 u, out ivec3 voxel) {
  vec3 c = u - 0.5;
  ivec3 base = ivec3(floor(c));
  vec3 f = c - vec3(base);
  uint best = 0u;
  float best_w = -1.0;
  voxel = ivec3(-1);
  for (int corner = 0; corner < 8; ++corner) {
    ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    uint l = label_at(base + d);
    if (l == 0u) continue;
    vec3 w3 = mix(1.0 - f, f, vec3(d));
    float w = w3.x * w3.y * w3.z;
    if (w > best_w) {
      best_w = w;
      best = l;
      voxel = base + d;
    }
  }
  return best;
}

// The solid voxel whose centre is nearest u (its label; the voxel in `voxel`), among those
// within kSmoothRadius (2) of the 8 voxels around u. The field is at or above the level at u only
// if one of those 8 has a solid voxel within the smoothing radius, so one is always found.
uint nearest_label(vec3 u, out ivec3 voxel) {
  ivec3 base = ivec3(floor(u - 0.5));
  uint best = 0u;
  float best_d = 1e30;
  voxel = ivec3(-1);
  for (int k = -2; k <= 3; ++k) {
    for (int j = -2; j <= 3; ++j) {
      for (int i = -2; i <= 3; ++i) {
        ivec3 v = base + ivec3(i, j, k);
        uint l = label_at(v);
        vec3 r = vec3(v) + 0.5 - u;
        float d = dot(r, r);
        if (l != 0u && d < best_d) {
          best_d = d;
          best = l;
          voxel = v;
        }
      }
    }
  }
  return best;
}

void main() {
  inv_shape = 1.0 / u_shape;
#ifdef ORTHOGRAPHIC
  vec3 dir = u_ray_dir;
  vec3 eye = v_voxel - u_ray_back * dir;
#elif defined(FROM_PIXELS)
  vec3 eye = u_eye;
  vec4 through = u_voxel_from_clip * vec4(gl_FragCoord.xy / u_viewport * 2.0 - 1.0, 0.5, 1.0);
  vec3 dir = normalize(through.xyz / through.w - eye);
#else
  vec3 eye = u_eye;
  vec3 dir = normalize(v_voxel - eye);
#endif
  vec3 inv_dir = 1.0 / dir;
  vec3 a = (vec3(0.0) - eye) * inv_dir;
  vec3 b = (u_shape - eye) * inv_dir;
  vec3 near_t = min(a, b);
  vec3 far_t = max(a, b);
  float t_enter = max(max(near_t.x, near_t.y), max(near_t.z, 0.0));
  float t_exit = min(min(far_t.x, far_t.y), far_t.z);

  // Samples sit on one lattice, t = t_enter + m * dt, with or without skipping.
  const float dt = 0.5;
  int m = 0;
  int m_below = 0;  // the last sample known to be below the level
  bool hit = false;
  int budget = int(4.0 * (u_shape.x + u_shape.y + u_shape.z)) + 16;
  float t = t_enter;
#if EMPTY_SPACE_SKIPPING
  ivec3 brick_shape = textureSize(u_bricks, 0);
  float bs = float(u_brick_size);
  while (!hit && t <= t_exit && budget > 0) {
    vec3 p = eye + t * dir;
    ivec3 brick = clamp(ivec3(floor(p / bs)), ivec3(0), brick_shape - 1);
    uint dist = texelFetch(u_bricks, brick, 0).r;
    --budget;
    if (dist > 0u) {
      // Every brick within dist - 1 of this one is empty: leave that cube in one jump.
      vec3 lo = vec3(brick - ivec3(dist - 1u)) * bs;
      vec3 hi = vec3(brick + ivec3(dist)) * bs;
      float t_jump = exit_distance(eye, inv_dir, lo, hi);
      m_below = max(m, int(floor((t_jump - t_enter) / dt)));
      m = m_below + 1;
      t = t_enter + float(m) * dt;
      continue;
    }
    float t_brick = min(exit_distance(eye, inv_dir, vec3(brick) * bs, vec3(brick + 1) * bs),
                        t_exit);
    // At least one sample per visit, so rounding at a brick face cannot stall the ray.
    do {
      if (field(eye + t * dir) >= u_level) {
        hit = true;
        break;
      }
      m_below = m;
      ++m;
      t = t_enter + float(m) * dt;
      --budget;
    } while (t <= t_brick && budget > 0);
  }
#else
  for (; t <= t_exit && budget > 0; --budget) {
    if (field(eye + t * dir) >= u_level) {
      hit = true;
      break;
    }
    m_below = m;
    ++m;
    t = t_enter + float(m) * dt;
  }
#endif
#ifdef DEBUG_STEPS
  o_color = vec4(0.0);
  o_depth = float(int(4.0 * (u_shape.x + u_shape.y + u_shape.z)) + 16 - budget);
  gl_FragDepth = 0.5;
  return;
#endif
  if (!hit) discard;

  if (m > 0) {
    float lo = t_enter + float(m_below) * dt, hi = t;
    for (int i = 0; i < 4; ++i) {
      float mid = 0.5 * (lo + hi);
      if (field(eye + mid * dir) >= u_level) {
        hi = mid;
      } else {
        lo = mid;
      }
    }
    t = hi;
  }
  vec3 u = eye + t * dir;

  vec4 camera = u_camera_from_voxel * vec4(u, 1.0);
  vec4 clip = u_clip_from_voxel * vec4(u, 1.0);
#ifdef DEPTH_ONLY
  gl_FragDepth = clip.z / clip.w;
  return;
#endif

  // The gradient from the four corners of a tetrahedron around the hit (it points inwards).
  const float h = NORMAL_SPAN;
  float a0 = field(u + h * vec3(1, 1, 1)), a1 = field(u + h * vec3(1, -1, -1));
  float a2 = field(u + h * vec3(-1, 1, -1)), a3 = field(u + h * vec3(-1, -1, 1));
  vec3 g = vec3(a0 + a1 - a2 - a3, a0 - a1 + a2 - a3, a0 - a1 - a2 + a3);

  // The voxel a quarter voxel in from the surface (along the gradient, so every view sees the
  // same voxel at a surface point) is solid almost always; thin features fall back to the solid
  // neighbour with the largest trilinear weight. Where the smoothing rounds a concave corner, the
  // surface can pass over eight empty voxels: the label is then the nearest solid voxel's, the
  // material whose occupancy raised the field there. Every pass names that one voxel, so a
  // pixel with the volume's id always has its label and voxel.
  vec3 inward = dot(g, g) > 1e-12 ? normalize(g) : dir;
  ivec3 voxel = ivec3(floor(u + 0.25 * inward));
  uint label = label_at(voxel);
  if (label == 0u) label = dominant_label(u, voxel);
  if (label == 0u) label = nearest_label(u, voxel);
  if (label == 0u) discard;  // cannot happen (see nearest_label); never an unlabelled hit
  vec3 base = texelFetch(u_colors, ivec2(int(label & 255u), int(label >> 8)), 0).rgb;
#if SHADE
  vec3 n = normalize(u_normal_from_voxel * -g);
  if (dot(n, camera.xyz) > 0.0) n = -n;  // grazing hits: light the side the camera sees
  o_color = vec4(lit(base, n, camera.xyz), 1.0);
#else
  o_color = vec4(base, 1.0);
#endif
  o_segmentation = vec4(base, 1.0);
  o_depth = camera.z;
  o_label = label;
  o_instance = u_instance;
  ivec3 shape = ivec3(u_shape);
  o_voxel = voxel.x + shape.x * (voxel.y + shape.y * voxel.z);
  gl_FragDepth = clip.z / clip.w;
}
