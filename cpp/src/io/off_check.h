#pragma once

#include <string>

namespace ambfplus::io {

/// Checks an OFF file's counts before assimp reads it: the vertex and face counts after the OFF
/// keyword (one vertex or face a line) cannot exceed the lines the file has, since Debian's
/// assimp allocates by the counts first (a 3 GB allocation for a 100-byte file). Throws
/// ConfigError naming the file and the counts. A file whose counts cannot be read is left to
/// assimp, which reports it.
void check_off(const std::string& path, const std::string& bytes);

}  // namespace ambfplus::io
