#version 450 core
// An RGBA image blended over the window (text and marks of a session's status).

in vec2 v_uv;
uniform sampler2D u_overlay;
layout(location = 0) out vec4 o_color;

void main() { o_color = texture(u_overlay, v_uv); }
