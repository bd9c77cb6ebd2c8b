#pragma once

#include <string>

namespace ambfplus::io {

/// True when bytes begin with the PLY magic line ("ply").
bool looks_like_ply(const std::string& bytes);

/// Checks a PLY file's structure before assimp reads it, since Debian's assimp hangs on a header
/// without end_header and crashes on faces that name missing vertices or rows that are not what
/// the header declares. Checks the header (format, elements, properties, end_header), every row of
/// every element (ASCII: one row per line, numbers of the declared types; binary: the bytes they
/// need), that face indices name existing vertices, and that nothing follows the last element.
/// Throws ConfigError naming the file and the line, element or byte at fault.
void check_ply(const std::string& path, const std::string& bytes);

}  // namespace ambfplus::io
