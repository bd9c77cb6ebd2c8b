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
// With LOOKS (Camera::looks) the rgb pass alone also gets ambient occlusion from the blurred
// occupancy, a bone texture fixed to the volume and a wet specular lobe; no other output changes.

#ifndef SHADE
#define SHADE 1
#endif
#ifndef LOOKS
#define LOOKS 0
#endif
#if LOOKS && SHADE
#define WET_SHININESS 220.0  // the wet lobe (lighting.glsl): sharp ...
#define WET_GAIN 3.0         // ... and brighter than the material's own
#endif

#include "lighting.glsl"

#ifndef NORMAL_SPAN
#define NORMAL_SPAN 1.2  // VolumeData::kNormalSpan
#endif
#ifndef EMPTY_SPACE_SKIPPING
#define EMPTY_SPACE_SKIPPING 1
#endif

in vec3 v_voxel;

uniform vec3 u_shape;
uniform vec3 u_voxel_size;         // metres
uniform vec3 u_eye;                // camera position, voxel units
#ifndef SILHOUETTE_REACH
#define SILHOUETTE_REACH 12.0
#endif
#ifdef FROM_PIXELS
// Supersampling casts one ray per fragment of a densely packed target (SceneRenderer::
// supersample): each reads which lattice point of the camera's image its ray goes through, and
// the depths to search.
uniform mat4 u_voxel_from_clip;
uniform sampler2D u_packed_where;  // per texel: x the lattice column + reach / 4 (0: within the
                                   // range, 1: a silhouette, 2: no far end), y the row, z and w the
                                   // nearest and farthest camera z at which the pixel centres
                                   // around the point see a volume (w < 0: no ray)
uniform vec2 u_lattice_origin;     // where lattice point (0, 0) lies, pixels
uniform float u_lattice_step;      // pixels between lattice points
uniform vec2 u_image_size;         // the camera's image, pixels
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
uniform sampler3D u_intensity;     // CT intensity, 0..1 between its 2nd and 98th percentiles
uniform bool u_has_intensity;
uniform sampler3D u_obscurance;       // the obscurance field (ambient_occlusion), zero border
uniform vec3 u_obscurance_scale;      // voxel units to its texture coordinates
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

#if LOOKS && SHADE
// A hash of a lattice point, 0..1.
float lattice_hash(vec3 p) {
  p = fract(p * vec3(0.1031, 0.1030, 0.0973));
  p += dot(p, p.yxz + 33.33);
  return fract((p.x + p.y) * p.z);
}

// Smooth value noise, 0..1, one feature per unit.
float value_noise(vec3 x) {
  vec3 i = floor(x);
  vec3 f = fract(x);
  f = f * f * (3.0 - 2.0 * f);
  float n000 = lattice_hash(i), n100 = lattice_hash(i + vec3(1, 0, 0));
  float n010 = lattice_hash(i + vec3(0, 1, 0)), n110 = lattice_hash(i + vec3(1, 1, 0));
  float n001 = lattice_hash(i + vec3(0, 0, 1)), n101 = lattice_hash(i + vec3(1, 0, 1));
  float n011 = lattice_hash(i + vec3(0, 1, 1)), n111 = lattice_hash(i + vec3(1, 1, 1));
  return mix(mix(mix(n000, n100, f.x), mix(n010, n110, f.x), f.y),
             mix(mix(n001, n101, f.x), mix(n011, n111, f.x), f.y), f.z);
}

// Bone's mottled albedo at a point of the volume frame (metres): 1 +- 13%, features of about
// 1.2 mm and 0.4 mm. Fixed to the volume, so it never swims and both eyes see the same.
float bone_texture(vec3 p) {
  float t = 0.65 * value_noise(p * (1.0 / 1.2e-3)) + 0.35 * value_noise(p * (1.0 / 0.4e-3));
  return 1.0 + 0.26 * (t - 0.5);
}

// Ambient occlusion at surface point u (voxel units) with outward direction out_n, from the
// obscurance field: the share of solid voxels around a point, weighted by a Gaussian of 4 voxels
// (GpuVolume: the occupancy at half resolution, blurred). Read 4 and 10 voxels out along the
// normal, less what flat open ground gives there (a half-space seen through the same Gaussian),
// it is what creases, pits and cavities put around the point: they darken, open ground and
// edges keep their light.
float ambient_occlusion(vec3 u, vec3 out_n) {
  // Flat ground's share at d voxels: the normal tail Phi(-d / 4.1), 4.1 voxels being the
  // Gaussian's 2 cells with the cells' and trilinear filtering's spread.
  const float reach[2] = float[2](4.0, 10.0);
  const float flat_ground[2] = float[2](0.1646, 0.0074);
  const float weight[2] = float[2](0.6, 0.4);
  float occluded = 0.0;
  for (int i = 0; i < 2; ++i) {
    float g = texture(u_obscurance, (u + reach[i] * out_n) * u_obscurance_scale).r;
    occluded += weight[i] * clamp((g - flat_ground[i]) / (1.0 - flat_ground[i]), 0.0, 1.0);
  }
  return 1.0 - 1.3 * min(occluded, 0.7);
}
#endif

void main() {
  inv_shape = 1.0 / u_shape;
#ifdef ORTHOGRAPHIC
  vec3 dir = u_ray_dir;
  vec3 eye = v_voxel - u_ray_back * dir;
#elif defined(FROM_PIXELS)
  vec4 where = texelFetch(u_packed_where, ivec2(gl_FragCoord.xy), 0);
  if (where.w < 0.0) discard;
  vec2 pixel = u_lattice_origin + vec2(floor(where.x), where.y) * u_lattice_step;
  vec3 eye = u_eye;
  vec4 through = u_voxel_from_clip * vec4(pixel / u_image_size * 2.0 - 1.0, 0.5, 1.0);
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
#ifdef FROM_PIXELS
  // A sample searches the depths at which the pixel centres around it (those within a pixel
  // along each axis) see a volume, widened by 3 voxels (and at a silhouette their spread) on
  // either side, with no far end where one of them shows a mesh or nothing (a surface the
  // centres see is found in a few steps, and a ray that passes it ends there instead of grazing
  // on): only a feature thinner than a pixel, missed by all of them, could lie outside. None of
  // them seeing one, no ray is cast (SceneRenderer::supersample). Where the search would start
  // inside the surface it starts at the box instead.
  vec3 range = vec3(where.z, where.w, fract(where.x) * 4.0);
  float z_near = range.x, z_far = range.y;
  bool open_far = range.z > 1.5;
  float reach = range.z > 0.5 ? SILHOUETTE_REACH : 3.0;
  float z0 = (u_camera_from_voxel * vec4(eye, 1.0)).z;
  float dz = (u_camera_from_voxel * vec4(dir, 0.0)).z;
  if (z_far < 0.0 || dz <= 0.0) {
    t = t_exit + 1.0;  // no search
  } else {
    // Near a silhouette the depth runs on past the centres: add their spread on either side.
    // Where all of them see a volume, the surface between them lies within their depths (a
    // slope's depths span the pixel, an inner edge's side wall lies between its top and floor).
    float spread = range.z > 0.5 ? (z_far - z_near) / dz : 0.0;
    if (!open_far) t_exit = min(t_exit, (z_far - z0) / dz + reach + spread);
    float m_near = floor(((z_near - z0) / dz - 3.0 - spread - t_enter) / dt);
    if (m_near > 0.0 && t_enter + m_near * dt <= t_exit &&
        field(eye + (t_enter + m_near * dt) * dir) < u_level) {
      m = int(m_near);
      m_below = m;
      t = t_enter + float(m) * dt;
    }
  }
#endif
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
  vec4 entry = texelFetch(u_colors, ivec2(int(label & 255u), int(label >> 8)), 0);
  vec3 base = entry.rgb;  // alpha: 1 for bone (is_bone), which alone takes the bone texture
#if SHADE
  vec3 n = normalize(u_normal_from_voxel * -g);
  if (dot(n, camera.xyz) > 0.0) n = -n;  // grazing hits: light the side the camera sees
#if LOOKS
  // Albedo darkened by occlusion (ambient and diffuse light alike) and, on bone, mottled like
  // bone, or by the CT intensity a voxel inside the surface where the volume has one. Soft
  // tissue (nerves, vessels, dura) keeps its even colour.
  float grain = u_has_intensity
                    ? 1.0 + 0.26 * (texture(u_intensity, (u + inward) * inv_shape).r - 0.5)
                    : bone_texture(u * u_voxel_size);
  grain = mix(1.0, grain, entry.a);
  vec3 albedo = base * (grain * ambient_occlusion(u, -inward));
  o_color = vec4(lit(albedo, n, camera.xyz), 1.0);
#else
  o_color = vec4(lit(base, n, camera.xyz), 1.0);
#endif
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
