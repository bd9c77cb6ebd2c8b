#version 450 core
// Supersampling: marks the pixels whose k x k samples may differ: where a neighbour (of the 8) shows another
// object or label, a depth more than 1% apart, or a colour more than u_contrast apart in a
// channel (shadow edges, textures, highlights). The passes it reads are exact per pixel.

uniform sampler2D u_rgb;
uniform sampler2D u_depth;
uniform usampler2D u_label;
uniform isampler2D u_instance;
uniform float u_contrast;

layout(location = 0) out uint o_mask;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(u_instance, 0) - 1;
  int id = texelFetch(u_instance, p, 0).r;
  uint label = texelFetch(u_label, p, 0).r;
  float z = texelFetch(u_depth, p, 0).r;
  vec3 c = texelFetch(u_rgb, p, 0).rgb;
  uint edge = 0u;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), last);
      float zq = texelFetch(u_depth, q, 0).r;
      vec3 d = abs(texelFetch(u_rgb, q, 0).rgb - c);
      if (texelFetch(u_instance, q, 0).r != id || texelFetch(u_label, q, 0).r != label ||
          abs(zq - z) > 0.01 * max(abs(z), abs(zq)) || max(max(d.r, d.g), d.b) > u_contrast) {
        edge = 1u;
      }
    }
  }
  o_mask = edge;
}
