#version 450 core
// Shaded colour, and metric depth from the perspective-correct camera-frame position: exact and
// linear whatever the depth buffer holds, also on triangles clipped from points at infinity (where
// gl_FragCoord.w is not 1/z because the clipped vertices carry a homogeneous scale).

#include "lighting.glsl"

in vec4 v_position;
in vec3 v_normal;

uniform vec4 u_color;

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out uint o_label;  // volume labels only

void main() {
  vec3 p = v_position.xyz / v_position.w;
  o_depth = p.z;
  o_label = 0u;
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  o_color = vec4(lit(u_color.rgb, n, p), u_color.a);
}
