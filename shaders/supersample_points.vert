#version 450 core
// Supersampling: one point per 4 x 4 tile of the lattice with a point to sample (the marker),
// or per 2 x 2 block of pixels with one to sample (the resolve).

layout(location = 0) in vec2 a_centre;  // the tile's or block's centre, from the bottom left

uniform vec2 u_size;         // the lattice's or the camera's image, pixels
uniform float u_point_size;  // 4 in the lattice, 2 in the camera's image

void main() {
  gl_Position = vec4(a_centre / u_size * 2.0 - 1.0, 0.5, 1.0);
  gl_PointSize = u_point_size;
}
