#version 450 core
// The box of a volume, drawn to start one ray per covered pixel. Positions are the unit cube,
// scaled to voxel units (the grid spans [0, n] along each axis).

layout(location = 0) in vec3 a_position;

uniform vec3 u_shape;
uniform mat4 u_clip_from_voxel;

out vec3 v_voxel;

void main() {
  v_voxel = a_position * u_shape;
  gl_Position = u_clip_from_voxel * vec4(v_voxel, 1.0);
}
