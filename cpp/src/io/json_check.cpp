// The nesting check of a glTF file's JSON, done before assimp parses it recursively.

#include "io/json_check.h"

#include <cstdint>
#include <string>

#include "ambfplus/errors.h"

namespace ambfplus::io {

namespace {

std::uint32_t le32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

// Brackets outside strings, with escapes inside them skipped.
void check_depth(const std::string& path, const std::string& bytes, std::size_t begin,
                 std::size_t end) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = begin; i < end; ++i) {
    const char c = bytes[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > kMaxJsonDepth) {
        throw ConfigError(path, "its glTF JSON nests deeper than " + std::to_string(kMaxJsonDepth) +
                                    " levels (at byte " + std::to_string(i) +
                                    "): not a glTF file a tool wrote");
      }
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
}

}  // namespace

void check_gltf_json(const std::string& path, const std::string& bytes) {
  // Binary glTF: a 12-byte header ("glTF", version, length), then chunks (length, type, data);
  // the first is the JSON one.
  if (bytes.size() >= 20 && bytes.compare(0, 4, "glTF") == 0) {
    const std::size_t length = le32(bytes, 12);
    if (le32(bytes, 16) == 0x4E4F534Au) {  // "JSON"
      const std::size_t end = length > bytes.size() - 20 ? bytes.size() : 20 + length;
      check_depth(path, bytes, 20, end);
    }
    return;
  }
  const std::size_t first = bytes.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first != std::string::npos && bytes[first] == '{')
    check_depth(path, bytes, first, bytes.size());
}

}  // namespace ambfplus::io
