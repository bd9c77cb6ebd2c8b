// The size check of a binary STL file (80-byte header, uint32 count, 50 bytes per triangle:
// the format's public description), done before the file is handed to assimp.

#include "io/stl_check.h"

#include <cstdint>

#include "ambfplus/errors.h"

namespace ambfplus::io {

namespace {

constexpr std::size_t kHeaderBytes = 84;      // 80 bytes of text, then the triangle count
constexpr std::uint64_t kTriangleBytes = 50;  // normal, three vertices, attribute count

bool is_ascii_stl(const std::string& bytes) {
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  return start != std::string::npos && bytes.compare(start, 5, "solid") == 0 &&
         bytes.find('\0') == std::string::npos;
}

}  // namespace

void check_stl(const std::string& path, const std::string& bytes) {
  if (is_ascii_stl(bytes)) return;
  if (bytes.size() < kHeaderBytes) {
    throw ConfigError(path, "binary STL of " + std::to_string(bytes.size()) +
                                " bytes is shorter than its 84-byte header (80 bytes of text and "
                                "a triangle count)");
  }
  std::uint32_t count = 0;
  for (int b = 3; b >= 0; --b) {
    count = (count << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(b)]);
  }
  const std::uint64_t expected = kHeaderBytes + kTriangleBytes * count;
  if (expected != bytes.size()) {
    throw ConfigError(path, "binary STL: its header promises " + std::to_string(count) +
                                " triangles, which take 84 + 50 * " + std::to_string(count) +
                                " = " + std::to_string(expected) + " bytes, but the file has " +
                                std::to_string(bytes.size()) +
                                (bytes.size() < expected ? " (cut short)" : " (bytes left over)"));
  }
}

}  // namespace ambfplus::io
