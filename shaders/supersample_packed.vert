#version 450 core
// Supersampling: one triangle over the whole packed target, whose every fragment is one sample
// of the lattice (SceneRenderer::supersample). Its corners come from the vertex's index.

out vec3 v_voxel;  // unused: volume.frag's FROM_PIXELS rays start from their packed texel

void main() {
  vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);  // (0, 0), (2, 0), (0, 2)
  gl_Position = vec4(corner * 2.0 - 1.0, 0.5, 1.0);
  v_voxel = vec3(0.0);
}
