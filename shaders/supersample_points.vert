#version 450 core
// Supersampling: one point per 2 x 2 block of pixels to sample, covering the block's 2k x 2k
// samples of the k x k larger image (a block of a software rasteriser's, for k = 2, so that
// its lanes all work).

layout(location = 0) in vec2 a_centre;  // the block's centre, pixels from the bottom left

uniform vec2 u_size;        // the camera's image, pixels
uniform float u_point_size;  // 2k in the k x k larger image, 2 in the camera's

out vec3 v_voxel;  // unused: volume.frag's FROM_PIXELS rays start from the fragment's position

void main() {
  gl_Position = vec4(a_centre / u_size * 2.0 - 1.0, 0.5, 1.0);
  gl_PointSize = u_point_size;
  v_voxel = vec3(0.0);
}
