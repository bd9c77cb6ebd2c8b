#version 450 core
// Shadow maps: meshes write only their depth as seen from the light.

void main() {}
