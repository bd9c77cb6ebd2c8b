#version 450 core
// Supersampling: each texel of the packed target starts as what the meshes (or the background)
// show at its lattice point, at their depth, for the volumes' rays to be depth-tested against.

uniform sampler2D u_packed_where;   // x: the lattice column (+ a code), y: its row; w < 0: unused
uniform sampler2D u_lattice_color;  // the meshes' samples
uniform sampler2D u_lattice_depth;  // and their depth test

layout(location = 0) out vec4 o_color;

void main() {
  vec4 where = texelFetch(u_packed_where, ivec2(gl_FragCoord.xy), 0);
  if (where.w < 0.0) discard;
  ivec2 p = ivec2(floor(where.x), where.y);
  o_color = texelFetch(u_lattice_color, p, 0);
  gl_FragDepth = texelFetch(u_lattice_depth, p, 0).r;
}
