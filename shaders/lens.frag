#version 450 core
// A view's image through a head-mounted display's lens (PanoTools model): the window pixel at r
// from the lens centre (in units of u_radius of the viewport's width) shows the image at
// r (a r^3 + b r^2 + c r + d), each channel scaled by its aberration; black outside the image.

in vec2 v_uv;  // the viewport's (0, 0) at its bottom left... flipped by overlay.vert: row 0 top
uniform sampler2D u_image;  // the camera's target: its row 0 (image top) is texture row 0
uniform vec4 u_k;
uniform vec3 u_aberration;
uniform vec2 u_centre;  // fractions of the viewport, y from the bottom
uniform float u_radius;
uniform float u_aspect;
layout(location = 0) out vec4 o_color;

float channel(vec2 p, float scale, int c) {
  vec2 uv = u_centre + p * scale * vec2(1.0, u_aspect);
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 0.0;
  return texture(u_image, vec2(uv.x, 1.0 - uv.y))[c];
}

void main() {
  vec2 window = vec2(v_uv.x, 1.0 - v_uv.y);  // y from the bottom
  // Physical offsets in units of the viewport's width.
  vec2 p = (window - u_centre) * vec2(1.0, 1.0 / u_aspect);
  float r = length(p) / u_radius;
  float s = ((u_k.x * r + u_k.y) * r + u_k.z) * r + u_k.w;
  o_color = vec4(channel(p, s * u_aberration.r, 0), channel(p, s * u_aberration.g, 1),
                 channel(p, s * u_aberration.b, 2), 1.0);
}
