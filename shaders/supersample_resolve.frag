#version 450 core
// The box filter of supersampling: each marked pixel becomes the mean of its k x k samples;
// the others keep the colour of their one sample at the pixel centre. Drawn as the points of
// the blocks sampled.

uniform sampler2D u_samples;            // the k x k larger image
uniform usampler2D u_supersample_mask;  // 1 where a pixel is supersampled
uniform int u_supersample_factor;       // k

layout(location = 0) out vec4 o_color;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (texelFetch(u_supersample_mask, p, 0).r == 0u) discard;
  int k = u_supersample_factor;
  vec4 sum = vec4(0.0);
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) sum += texelFetch(u_samples, p * k + ivec2(i, j), 0);
  }
  o_color = sum / float(k * k);
}
