#version 450 core
// The resolve of supersampling: each marked pixel takes the mean of its lattice samples, blended
// over its own centre's colour by the blend constant (k = 2: its four corners, the mean weighted
// 1/2 against the centre; k = 3, 4: its k x k samples, which replace it). A sample is the
// volumes' packed one where a ray was cast for it, else the meshes' (or background) one. The
// other pixels keep the colour of their one sample. Drawn as the points of the pixel blocks.

uniform sampler2D u_samples;            // the lattice: meshes and background
uniform sampler2D u_packed_color;       // the volumes' samples, packed
uniform isampler2D u_lattice_index;     // per lattice point, its packed texel or -1
uniform usampler2D u_supersample_mask;  // 1 where a pixel is supersampled
uniform int u_supersample_factor;       // k

layout(location = 0) out vec4 o_color;

vec4 sample_at(ivec2 q) {
  ivec2 at = texelFetch(u_lattice_index, q, 0).xy;
  return at.x < 0 ? texelFetch(u_samples, q, 0) : texelFetch(u_packed_color, at, 0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (texelFetch(u_supersample_mask, p, 0).r == 0u) discard;
  int k = u_supersample_factor;
  vec4 sum = vec4(0.0);
  if (k == 2) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) sum += sample_at(p + ivec2(i, j));
    }
    o_color = sum * 0.25;
  } else {
    for (int j = 0; j < k; ++j) {
      for (int i = 0; i < k; ++i) sum += sample_at(p * k + ivec2(i, j));
    }
    o_color = sum / float(k * k);
  }
}
