#version 450 core
// Shaded colour (flat with SHADE 0, when no rgb pass is asked for), object id, segmentation
// colour, and metric depth from the perspective-correct camera-frame position: exact and linear
// whatever the depth buffer holds, also on triangles clipped from points at infinity (where
// gl_FragCoord.w is not 1/z because the clipped vertices carry a homogeneous scale).

#include "lighting.glsl"

#ifndef SHADE
#define SHADE 1
#endif

in vec4 v_position;
in vec3 v_normal;
in vec2 v_texcoord;

uniform vec4 u_color;
uniform int u_instance;  // the object's id
uniform vec3 u_segmentation_color;  // flat, as AMBF's preprocessing shader draws it
uniform bool u_textured;             // the diffuse colour is u_color x the texture's texel
uniform sampler2D u_diffuse_map;     // unit 0

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out uint o_label;  // volume labels only
layout(location = 3) out int o_instance;
layout(location = 4) out int o_voxel;  // volume voxels only
layout(location = 5) out vec4 o_segmentation;

void main() {
  vec3 p = v_position.xyz / v_position.w;
  o_depth = p.z;
  o_label = 0u;
  o_instance = u_instance;
  o_voxel = -1;
  o_segmentation = vec4(u_segmentation_color, 1.0);
#if SHADE
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec4 base = u_color;
  if (u_textured) base *= texture(u_diffuse_map, v_texcoord);
  o_color = vec4(lit(base.rgb, n, p), base.a);
#else
  o_color = u_color;
#endif
}
