// Supersampling of the rgb pass (#include "supersample.glsl"): with SUPERSAMPLE defined, a
// surface shader runs in a k x k larger image only under pixels the mask marks (mask.frag), and
// resolve.frag averages each marked pixel's k x k samples.

#ifdef SUPERSAMPLE
uniform usampler2D u_supersample_mask;  // 1 where a pixel is supersampled
uniform int u_supersample_factor;       // k

bool outside_supersample_mask() {
  return texelFetch(u_supersample_mask, ivec2(gl_FragCoord.xy) / u_supersample_factor, 0).r == 0u;
}
#endif
