#version 450 core
// A textured quad over the whole window: positions from the vertex index, no buffers.

out vec2 v_uv;

void main() {
  vec2 corner = vec2(gl_VertexID & 1, (gl_VertexID >> 1) & 1);
  // The overlay's row 0 is the window's top; texture row 0 is uploaded first (bottom in GL).
  v_uv = vec2(corner.x, 1.0 - corner.y);
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
