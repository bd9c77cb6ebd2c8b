#version 450 core
// Supersampling: the samples under the points start as background at the far plane, and the
// stencil marks them (the rest of the lattice is neither cleared nor shaded).

uniform vec4 u_background;

layout(location = 0) out vec4 o_color;

void main() {
  o_color = u_background;
  gl_FragDepth = 0.0;
}
