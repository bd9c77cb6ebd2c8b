#pragma once

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>

#include "ambfplus/errors.h"

namespace ambfplus {

/// ASCII lower case, for case-insensitive keywords ("BOX", "Box", "box").
inline std::string to_lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// Throws ConfigError naming the file, the line and the offending byte when text (line `line`
/// of a text file) is not UTF-8: names and messages built from it must reach Python as text.
inline void require_utf8(const std::string& path, int line, const std::string& text) {
  const std::size_t at = detail::utf8_error_offset(text);
  if (at == text.size()) return;
  char byte[8];
  std::snprintf(byte, sizeof(byte), "0x%02x", static_cast<unsigned char>(text[at]));
  throw ConfigError(path, "line " + std::to_string(line) + ", column " + std::to_string(at + 1) +
                              ": byte " + byte + " is not UTF-8 text (save the file as UTF-8)");
}

}  // namespace ambfplus
