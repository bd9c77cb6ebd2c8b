#version 450 core
// Meshes seen by a camera: positions into clip space, normals and positions into the camera frame
// (OpenCV: x right, y down, z forward). Positions may be homogeneous (w = 0 for points at infinity).

layout(location = 0) in vec4 a_position;  // w defaults to 1 when the buffer holds 3 components
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_texcoord;  // (0, 0) for meshes without texture coordinates

uniform mat4 u_model_view;   // camera from object
uniform mat4 u_projection;   // clip from camera
uniform mat3 u_normal_matrix;

out vec4 v_position;  // camera frame, homogeneous
out vec3 v_normal;    // camera frame
out vec2 v_texcoord;

void main() {
  v_position = u_model_view * a_position;
  v_normal = u_normal_matrix * a_normal;
  v_texcoord = a_texcoord;
  gl_Position = u_projection * v_position;
}
