#pragma once

#include <string>

namespace ambfplus::io {

/// How deep a glTF file's JSON may nest: real files nest under 20 levels; assimp's JSON reader
/// recurses once per level, so 200,000 nested brackets overflowed the stack.
constexpr int kMaxJsonDepth = 256;

/// Checks the nesting depth of the JSON a glTF file holds before assimp reads it: the whole file
/// when it is text (.gltf), the JSON chunk when it is binary glTF (magic "glTF"). Throws
/// ConfigError naming the file, the depth and where it was reached; other files pass.
void check_gltf_json(const std::string& path, const std::string& bytes);

}  // namespace ambfplus::io
