#pragma once

#include <string>

namespace ambfplus::io {

/// Checks a binary STL file's size against its header before assimp reads it: an 80-byte
/// header, a little-endian uint32 triangle count n, then exactly 50 bytes per triangle. A file
/// that starts with "solid" and holds no NUL byte is ASCII STL and left to assimp. Throws
/// ConfigError naming the file, the triangle count and the sizes expected and found (assimp
/// itself only says it cannot tell which kind of STL a cut file is).
void check_stl(const std::string& path, const std::string& bytes);

}  // namespace ambfplus::io
